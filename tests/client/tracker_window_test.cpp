// The request tracker's window (Host Link is half duplex: one request on the line at a
// time), its frame-size limit, and fail_sent() (an error answer ends only the request
// on the line).
#include <gtest/gtest.h>

#include "client/tracker_fixture.hpp"
#include "fins/host_link.hpp"

namespace fins::test {
namespace {

TEST_F(TrackerTest, WindowOfOneSendsTheNextOnlyAfterTheAnswer) {
    tracker.set_window(1);
    Outcome a, b, c;
    submit(a, {100ms, 0});
    submit(b, {100ms, 0});
    submit(c, {100ms, 0});
    ASSERT_EQ(wire.frames.size(), 1u);
    // The queued requests' clocks have not started: at t0 + 100 ms only the first times out.
    tracker.on_timer(t0 + 100ms);
    ASSERT_TRUE(a.result.has_value());
    EXPECT_EQ(a.result->error(), make_error_code(ClientError::timeout));
    ASSERT_EQ(wire.frames.size(), 2u);  // b went out when a ended
    EXPECT_FALSE(b.result.has_value());
    // b's answer sends c.
    tracker.on_frame(answer(wire.frames[1]), t0 + 150ms);
    ASSERT_TRUE(b.result.has_value());
    EXPECT_TRUE(b.result->has_value());
    ASSERT_EQ(wire.frames.size(), 3u);
    // A full window is reopened by answers and deadlines, never by a free SID: the next
    // deadline is c's, not "now".
    EXPECT_EQ(tracker.next_deadline(), t0 + 250ms);
}

TEST_F(TrackerTest, FailSentEndsOnlyTheRequestOnTheLine) {
    tracker.set_window(1);
    Outcome a, b;
    submit(a);
    submit(b);
    tracker.fail_sent(make_error_code(HostLinkEndCode::fcs_error), t0 + 1ms);
    ASSERT_TRUE(a.result.has_value());
    EXPECT_EQ(a.result->error(), make_error_code(HostLinkEndCode::fcs_error));
    EXPECT_FALSE(b.result.has_value());
    EXPECT_EQ(wire.frames.size(), 2u);  // b is on the line now
    EXPECT_EQ(tracker.in_flight(), 1u);
}

TEST_F(TrackerTest, W342_3_5_HostLinkFrameLimitRefusesLongerRequests) {
    tracker.set_max_frame(host_link_max_fins_command);
    Outcome o;
    std::vector<std::uint8_t> params(host_link_max_parameter_bytes + 1);
    auto r = tracker.submit(write_code, params, {}, o.callback(), t0);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(ClientError::request_too_long));
    params.pop_back();
    EXPECT_TRUE(tracker.submit(write_code, params, {}, o.callback(), t0));
}

}  // namespace
}  // namespace fins::test
