// RequestTracker and SidPool: a service ID that may still get a late answer is not
// handed out again (issue 7 item 1; engine/sid_pool.hpp). Fake wire, fake clock.
#include <gtest/gtest.h>

#include <vector>

#include "client/tracker_fixture.hpp"
#include "engine/request_tracker.hpp"

using namespace fins;
using namespace fins::test;
using namespace std::chrono_literals;

namespace {

// Issue 7 item 1: a SID whose request timed out may still get that request's answer; it
// is not handed out again until its quarantine ends, even with 256 requests waiting.
TEST_F(TrackerTest, TimedOutServiceIdIsQuarantinedAndRequestsWaitRatherThanReuseIt) {
    tracker.set_quarantine(200ms);
    std::vector<Outcome> first(256);
    for (auto& o : first)
        submit(o, RequestTiming{100ms, 0}, t0);
    std::vector<std::vector<std::uint8_t>> sent = wire.frames;
    for (std::size_t i = 0; i < sent.size(); ++i)
        if (sent[i][9] != 5) tracker.on_frame(answer(sent[i]), t0 + 1ms);
    tracker.on_timer(t0 + 100ms);
    ASSERT_TRUE(first[5].result && !*first[5].result);
    EXPECT_TRUE(tracker.service_ids().is_quarantined(5));

    std::vector<Outcome> second(256);
    for (std::size_t i = 0; i < 255; ++i)
        EXPECT_NE(submit(second[i], RequestTiming{1s, 0}, t0 + 110ms), 5);
    const auto frames_before = wire.frames.size();
    ASSERT_TRUE(tracker.submit(read_code, read_params, RequestTiming{1s, 0}, second[255].callback(),
                               t0 + 110ms));
    EXPECT_EQ(wire.frames.size(), frames_before) << "waits: the only free SID is quarantined";
    EXPECT_EQ(tracker.stats().waited_for_id, 1u);
    EXPECT_EQ(tracker.next_deadline(), t0 + 300ms) << "the end of SID 5's quarantine";
    // The late answer to the timed-out request arrives meanwhile: stale, not a match.
    EXPECT_EQ(tracker.on_frame(answer(sent[5]), t0 + 150ms), RequestTracker::Disposition::stale);
    tracker.on_timer(t0 + 300ms);
    ASSERT_EQ(wire.frames.size(), frames_before + 1);
    EXPECT_EQ(wire.frames.back()[9], 5);
    EXPECT_FALSE(second[255].result) << "its clock started when it was sent";
    EXPECT_EQ(tracker.next_deadline(), t0 + 1110ms);
}

TEST_F(TrackerTest, RetransmittedServiceIdIsQuarantinedEvenWhenAnswered) {
    tracker.set_quarantine(200ms);
    Outcome o;
    const auto sid = submit(o, RequestTiming{100ms, 1});
    tracker.on_timer(t0 + 100ms);
    ASSERT_EQ(wire.frames.size(), 2u);
    EXPECT_EQ(tracker.on_frame(answer(wire.frames[1]), t0 + 110ms),
              RequestTracker::Disposition::matched);
    EXPECT_TRUE(tracker.service_ids().is_quarantined(sid)) << "the first attempt may answer too";
    EXPECT_EQ(tracker.stats().quarantined, 1u);
    EXPECT_EQ(tracker.on_frame(answer(wire.frames[0]), t0 + 150ms),
              RequestTracker::Disposition::stale);
    EXPECT_EQ(tracker.stats().quarantined, 1u) << "an awaited late answer is no new evidence";
}

// A duplicate of an answer that was already consumed shows that the network duplicates:
// SIDs released cleanly just before may get a duplicate too, so they rest as well.
TEST_F(TrackerTest, DuplicateAnswerQuarantinesRecentlyReleasedIds) {
    tracker.set_quarantine(200ms);
    Outcome a, b;
    const auto sid_a = submit(a, {}, t0);
    const auto sid_b = submit(b, {}, t0);
    const auto answer_a = answer(wire.frames[0]);
    tracker.on_frame(answer_a, t0 + 1ms);
    tracker.on_frame(answer(wire.frames[1]), t0 + 2ms);
    EXPECT_FALSE(tracker.service_ids().is_quarantined(sid_a));
    EXPECT_FALSE(tracker.service_ids().is_quarantined(sid_b));
    EXPECT_EQ(tracker.on_frame(answer_a, t0 + 3ms), RequestTracker::Disposition::stale);
    EXPECT_TRUE(tracker.service_ids().is_quarantined(sid_a));
    EXPECT_TRUE(tracker.service_ids().is_quarantined(sid_b));
    Outcome c;
    submit(c, {}, t0 + 4ms);
    EXPECT_TRUE(tracker.service_ids().is_quarantined(sid_a) &&
                tracker.service_ids().is_quarantined(sid_b));
    tracker.on_frame(answer(wire.frames.back()), t0 + 5ms);
    EXPECT_TRUE(tracker.service_ids().is_quarantined(wire.frames.back()[9]))
        << "while the network is troubled, clean SIDs rest too";
}

}  // namespace
