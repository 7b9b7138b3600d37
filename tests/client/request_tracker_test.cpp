// RequestTracker with a fake wire and a fake clock: no sockets, no sleeps.
#include "engine/request_tracker.hpp"
#include "client/tracker_fixture.hpp"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

using namespace fins;
using namespace std::chrono_literals;

namespace {

using namespace fins::test;

TEST_F(TrackerTest, BuildsTheRequestFrameAndMatchesTheResponse) {
    Outcome o;
    auto id = submit(o);
    ASSERT_EQ(wire.frames.size(), 1u);
    const std::vector<std::uint8_t> expected{0x80, 0x00, 0x02, 0x00, 0x0A, 0x00, 0x00, 0x14, 0x00,
                                             id,   0x01, 0x01, 0x82, 0x00, 0x0A, 0x00, 0x00, 0x0A};
    EXPECT_EQ(wire.frames[0], expected);
    EXPECT_EQ(tracker.in_flight(), 1u);
    EXPECT_EQ(tracker.next_deadline(), t0 + default_timeout);

    auto response = answer(wire.frames[0], 0x0000, {0x12, 0x34});
    EXPECT_EQ(tracker.on_frame(response, t0 + 1ms), RequestTracker::Disposition::matched);
    ASSERT_TRUE(o.result && *o.result);
    EXPECT_EQ(o.data, (std::vector<std::uint8_t>{0x12, 0x34}));
    EXPECT_EQ(tracker.in_flight(), 0u);
    EXPECT_FALSE(tracker.next_deadline());
    EXPECT_EQ(tracker.stats().completed, 1u);
}

TEST_F(TrackerTest, EndCodesAreHandedThroughUninterpreted) {
    Outcome o;
    submit(o);
    tracker.on_frame(answer(wire.frames[0], 0x1103), t0);
    ASSERT_TRUE(o.result && *o.result);
    EXPECT_EQ((*o.result)->code.raw(), 0x1103);
}

void answer_in_reverse(std::size_t n) {
    FakeWire wire;
    RequestTracker tracker{wire};
    tracker.link_up(plc, host, t0);
    std::vector<Outcome> outcomes(n);
    for (std::size_t i = 0; i < n; ++i) {
        std::array<std::uint8_t, 2> params{static_cast<std::uint8_t>(i >> 8),
                                           static_cast<std::uint8_t>(i)};
        ASSERT_TRUE(tracker.submit(read_code, params, {}, outcomes[i].callback(), t0).has_value());
    }
    ASSERT_EQ(tracker.in_flight(), n);
    for (std::size_t i = n; i-- > 0;) {
        // Echo the request's parameters as data so each answer is recognisable.
        auto req = decode_request(wire.frames[i]);
        std::vector<std::uint8_t> data(req->parameters.begin(), req->parameters.end());
        EXPECT_EQ(tracker.on_frame(answer(wire.frames[i], 0, data), t0 + 1ms),
                  RequestTracker::Disposition::matched);
    }
    for (std::size_t i = 0; i < n; ++i) {
        ASSERT_TRUE(outcomes[i].result && *outcomes[i].result) << i;
        EXPECT_EQ(outcomes[i].data, (std::vector<std::uint8_t>{static_cast<std::uint8_t>(i >> 8),
                                                               static_cast<std::uint8_t>(i)}));
    }
    EXPECT_EQ(tracker.in_flight(), 0u);
    EXPECT_EQ(tracker.stats().completed, n);
}

TEST(TrackerWindow, ThirtyTwoInFlightAnsweredInReverseOrder) {
    answer_in_reverse(32);
}
TEST(TrackerWindow, TwoHundredFiftySixInFlightAnsweredInReverseOrder) {
    answer_in_reverse(256);
}

TEST_F(TrackerTest, The257thRequestIsRefused) {
    std::vector<Outcome> outcomes(256);
    for (auto& o : outcomes)
        submit(o);
    Outcome extra;
    RequestTracker::Completion cb = extra.callback();
    auto id = tracker.submit(read_code, read_params, {}, std::move(cb), t0);
    ASSERT_FALSE(id);
    EXPECT_EQ(id.error(), make_error_code(ClientError::too_many_in_flight));
    EXPECT_TRUE(cb) << "a refused completion is not consumed";
    EXPECT_FALSE(extra.result);
}

TEST_F(TrackerTest, CleanServiceIdsAreReusedLeastRecentlyUsedFirst) {
    auto t = t0;
    auto step = [&t] { return t += 1ms; };  // longer than a clean SID's minimum rest
    Outcome a, b;
    EXPECT_EQ(submit(a, {}, step()), 0);
    EXPECT_EQ(submit(b, {}, step()), 1);
    tracker.on_frame(answer(wire.frames[0]), step());
    Outcome c;
    EXPECT_EQ(submit(c, {}, step()), 2) << "SID 0 is free but must not be reused yet";
    // Walk to the end: 3..255, completing each so only SIDs 1 and 2 stay busy.
    for (int i = 3; i < 256; ++i) {
        Outcome o;
        auto id = submit(o, {}, step());
        EXPECT_EQ(id, i);
        tracker.on_frame(answer(wire.frames.back()), step());
    }
    tracker.on_frame(answer(wire.frames[2]), step());  // frees SID 2, after 0 and 3..255
    Outcome wrap1, wrap2;
    EXPECT_EQ(submit(wrap1, {}, step()), 0) << "freed first, used first";
    EXPECT_EQ(submit(wrap2, {}, step()), 3);
    EXPECT_EQ(tracker.stats().quarantined, 0u) << "every SID was clean";
}

TEST_F(TrackerTest, ResponseForAServiceIdNotInFlightIsStale) {
    Outcome o;
    submit(o);
    auto response = answer(wire.frames[0]);
    response[9] = 0x77;
    EXPECT_EQ(tracker.on_frame(response, t0), RequestTracker::Disposition::stale);
    EXPECT_EQ(tracker.stats().stale_discarded, 1u);
    EXPECT_FALSE(o.result);
    EXPECT_EQ(tracker.in_flight(), 1u);
}

TEST_F(TrackerTest, DuplicateResponseIsStale) {
    Outcome o;
    submit(o);
    auto response = answer(wire.frames[0]);
    EXPECT_EQ(tracker.on_frame(response, t0), RequestTracker::Disposition::matched);
    EXPECT_EQ(tracker.on_frame(response, t0), RequestTracker::Disposition::stale);
    EXPECT_EQ(tracker.stats().stale_discarded, 1u);
    EXPECT_EQ(tracker.stats().completed, 1u);
}

TEST_F(TrackerTest, WrongCommandCodeIsStaleAndTheRequestStaysInFlight) {
    Outcome o;
    submit(o);
    auto response = answer(wire.frames[0]);
    response[11] = 0x02;  // 01 02 instead of 01 01
    EXPECT_EQ(tracker.on_frame(response, t0), RequestTracker::Disposition::stale);
    EXPECT_FALSE(o.result);
    EXPECT_EQ(tracker.on_frame(answer(wire.frames[0]), t0), RequestTracker::Disposition::matched);
}

TEST_F(TrackerTest, MalformedFramesAreDiscardedAndCounted) {
    Outcome o;
    submit(o);
    const auto good = answer(wire.frames[0]);
    // Shorter than header + command + end code, at every length.
    for (std::size_t n = 0; n < 14; ++n)
        EXPECT_EQ(tracker.on_frame(Bytes{good.data(), n}, t0), RequestTracker::Disposition::invalid)
            << n;
    auto command = good;
    command[0] = 0x80;  // no response bit: a command, not an answer
    EXPECT_EQ(tracker.on_frame(command, t0), RequestTracker::Disposition::invalid);
    auto relay = good;
    relay[12] |= 0x80;  // relay-error bit without the relay word
    EXPECT_EQ(tracker.on_frame(relay, t0), RequestTracker::Disposition::invalid);
    auto wrong_node = good;
    wrong_node[7] = 11;  // answered by node 11, asked node 10
    EXPECT_EQ(tracker.on_frame(wrong_node, t0), RequestTracker::Disposition::invalid);
    auto wrong_unit = good;
    wrong_unit[5] = 0x10;  // addressed to unit 10, we are unit 00
    EXPECT_EQ(tracker.on_frame(wrong_unit, t0), RequestTracker::Disposition::invalid);
    EXPECT_EQ(tracker.stats().invalid_discarded, 18u);
    EXPECT_FALSE(o.result);
    EXPECT_EQ(tracker.on_frame(good, t0), RequestTracker::Disposition::matched);
}

TEST_F(TrackerTest, AnAnswerFromAnotherNodeIsDroppedAndNamesThatNode) {
    Outcome o;
    submit(o);
    EXPECT_FALSE(tracker.other_node());
    auto from_11 = answer(wire.frames[0]);
    from_11[7] = 11;  // SA1: answered by node 11, asked node 10
    EXPECT_EQ(tracker.on_frame(from_11, t0), RequestTracker::Disposition::invalid);
    EXPECT_FALSE(o.result) << "node 10 was asked: node 11's answer completes nothing";
    EXPECT_EQ(tracker.stats().other_node_answers, 1u);
    EXPECT_EQ(tracker.stats().invalid_discarded, 1u);
    ASSERT_TRUE(tracker.other_node());
    EXPECT_EQ(tracker.other_node()->node, 11);
    auto wrong_unit = answer(wire.frames[0]);
    wrong_unit[5] = 0x10;  // another unit: not a node mix-up
    EXPECT_EQ(tracker.on_frame(wrong_unit, t0), RequestTracker::Disposition::invalid);
    EXPECT_EQ(tracker.stats().other_node_answers, 1u);
    EXPECT_EQ(tracker.on_frame(answer(wire.frames[0]), t0), RequestTracker::Disposition::matched);
    EXPECT_FALSE(tracker.other_node()) << "a matching answer clears it";
}

TEST(TrackerAddresses, LocalNodeZeroAcceptsTheRespondersRealAddress) {
    FakeWire wire;
    RequestTracker tracker{wire};
    tracker.link_up(NodeAddress{0, 0, 0}, host, t0);
    Outcome o;
    ASSERT_TRUE(tracker.submit(read_code, read_params, {}, o.callback(), t0));
    auto response = answer(wire.frames[0], 0, {}, NodeAddress{3, 42, 0});
    EXPECT_EQ(response[6], 3);
    EXPECT_EQ(response[7], 42);
    EXPECT_EQ(tracker.on_frame(response, t0), RequestTracker::Disposition::matched);
}

TEST_F(TrackerTest, RetransmitsTheIdenticalFrameThenTimesOut) {
    Outcome o;
    submit(o, RequestTiming{100ms, 2});
    ASSERT_EQ(wire.frames.size(), 1u);
    tracker.on_timer(t0 + 99ms);
    EXPECT_EQ(wire.frames.size(), 1u) << "not due yet";
    EXPECT_EQ(tracker.next_deadline(), t0 + 100ms);
    tracker.on_timer(t0 + 100ms);
    tracker.on_timer(t0 + 200ms);
    ASSERT_EQ(wire.frames.size(), 3u);
    EXPECT_EQ(wire.frames[1], wire.frames[0]);
    EXPECT_EQ(wire.frames[2], wire.frames[0]);
    EXPECT_FALSE(o.result);
    EXPECT_EQ(tracker.next_deadline(), t0 + 300ms);
    tracker.on_timer(t0 + 300ms);
    ASSERT_TRUE(o.result);
    ASSERT_FALSE(*o.result);
    EXPECT_EQ(o.result->error(), make_error_code(ClientError::timeout));
    EXPECT_EQ(wire.frames.size(), 3u);
    EXPECT_EQ(tracker.stats().retransmitted, 2u);
    EXPECT_EQ(tracker.stats().timed_out, 1u);
    EXPECT_EQ(tracker.in_flight(), 0u);
    // The answer to an attempt that arrives after the failure is stale.
    EXPECT_EQ(tracker.on_frame(answer(wire.frames[0]), t0 + 301ms),
              RequestTracker::Disposition::stale);
}

TEST_F(TrackerTest, TimesOutWithoutRetriesAndZeroMeansTwoSeconds) {
    Outcome o;
    submit(o, RequestTiming{0ms, 0});
    EXPECT_EQ(tracker.next_deadline(), t0 + 2000ms);
    tracker.on_timer(t0 + 2000ms);
    ASSERT_TRUE(o.result && !*o.result);
    EXPECT_EQ(o.result->error(), make_error_code(ClientError::timeout));
    EXPECT_EQ(wire.frames.size(), 1u);
}

TEST_F(TrackerTest, AnswerToARetransmissionCompletesAndTheSecondIsADuplicate) {
    Outcome o;
    submit(o, RequestTiming{100ms, 1});
    tracker.on_timer(t0 + 100ms);
    ASSERT_EQ(wire.frames.size(), 2u);
    auto response = answer(wire.frames[1]);
    EXPECT_EQ(tracker.on_frame(response, t0 + 150ms), RequestTracker::Disposition::matched);
    EXPECT_EQ(tracker.on_frame(response, t0 + 160ms), RequestTracker::Disposition::stale);
    ASSERT_TRUE(o.result && *o.result);
}

TEST_F(TrackerTest, NextDeadlineIsTheEarliest) {
    Outcome a, b;
    submit(a, RequestTiming{500ms, 0}, t0);
    submit(b, RequestTiming{100ms, 0}, t0 + 50ms);
    EXPECT_EQ(tracker.next_deadline(), t0 + 150ms);
    tracker.on_timer(t0 + 150ms);
    EXPECT_TRUE(b.result);
    EXPECT_FALSE(a.result);
    EXPECT_EQ(tracker.next_deadline(), t0 + 500ms);
}

TEST_F(TrackerTest, NoResponseModeSetsIcfBit0AndKeepsNothing) {
    auto id = tracker.submit_no_response(write_code, read_params);
    ASSERT_TRUE(id);
    ASSERT_EQ(wire.frames.size(), 1u);
    EXPECT_EQ(wire.frames[0][0], 0x81);
    EXPECT_EQ(wire.frames[0][9], *id);
    EXPECT_EQ(tracker.in_flight(), 0u);
    EXPECT_FALSE(tracker.next_deadline());
    EXPECT_EQ(tracker.stats().sent, 1u);
    tracker.link_down(make_error_code(ClientError::connection_closed));
    auto refused = tracker.submit_no_response(write_code, read_params);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), make_error_code(ClientError::not_connected));
}

TEST_F(TrackerTest, LinkDownFailsEveryRequestInFlight) {
    std::vector<Outcome> outcomes(40);
    for (auto& o : outcomes)
        submit(o);
    tracker.link_down(make_error_code(ClientError::connection_closed));
    for (auto& o : outcomes) {
        ASSERT_TRUE(o.result && !*o.result);
        EXPECT_EQ(o.result->error(), make_error_code(ClientError::connection_closed));
    }
    EXPECT_EQ(tracker.in_flight(), 0u);
    EXPECT_FALSE(tracker.next_deadline());
    EXPECT_EQ(tracker.stats().failed, 40u);
    EXPECT_EQ(tracker.on_frame(answer(wire.frames[0]), t0), RequestTracker::Disposition::stale);
}

TEST_F(TrackerTest, RequestsAreHeldWhileTheLinkIsDownAndSentOnLinkUp) {
    tracker.link_down(make_error_code(ClientError::connection_closed));
    Outcome o;
    submit(o, RequestTiming{100ms, 1});
    EXPECT_TRUE(wire.frames.empty());
    EXPECT_EQ(tracker.in_flight(), 1u);
    // A timeout while held uses an attempt but sends nothing.
    tracker.on_timer(t0 + 100ms);
    EXPECT_TRUE(wire.frames.empty());
    const NodeAddress new_host{0, 33, 0};
    tracker.link_up(plc, new_host, t0 + 120ms);
    ASSERT_EQ(wire.frames.size(), 1u);
    EXPECT_EQ(wire.frames[0][7], 33) << "held frames get the addresses of the new link";
    EXPECT_EQ(tracker.on_frame(answer(wire.frames[0]), t0 + 130ms),
              RequestTracker::Disposition::matched);
    ASSERT_TRUE(o.result && *o.result);
}

TEST_F(TrackerTest, HeldRequestsFailWhenTheOpenFails) {
    tracker.link_down(make_error_code(ClientError::connection_closed));
    Outcome o;
    submit(o);
    tracker.link_down(make_error_code(TcpError::node_already_connected));
    ASSERT_TRUE(o.result && !*o.result);
    EXPECT_EQ(o.result->error(), make_error_code(TcpError::node_already_connected));
}

TEST_F(TrackerTest, ACompletionMaySubmitAgain) {
    int chained = 0;
    std::function<void(Result<ResponseView>)> again = [&](Result<ResponseView> r) {
        ASSERT_TRUE(r);
        if (++chained < 5) {
            ASSERT_TRUE(
                tracker.submit(read_code, read_params, {}, RequestTracker::Completion(again), t0));
        }
    };
    ASSERT_TRUE(tracker.submit(read_code, read_params, {}, RequestTracker::Completion(again), t0));
    for (std::size_t i = 0; i < 10 && tracker.in_flight() > 0; ++i)
        tracker.on_frame(answer(wire.frames.back()), t0);
    EXPECT_EQ(chained, 5);
    EXPECT_EQ(wire.frames.size(), 5u);
}

TEST_F(TrackerTest, ACompletionMaySubmitDuringLinkDown) {
    std::vector<Outcome> resubmitted(3);
    std::size_t next = 0;
    for (int i = 0; i < 3; ++i) {
        RequestTracker::Completion resubmit = [&](Result<ResponseView> r) {
            EXPECT_FALSE(r);
            submit(resubmitted[next++]);
        };
        ASSERT_TRUE(tracker.submit(read_code, read_params, {}, std::move(resubmit), t0));
    }
    tracker.link_down(make_error_code(ClientError::connection_closed));
    EXPECT_EQ(next, 3u);
    EXPECT_EQ(tracker.in_flight(), 3u) << "the new requests are held for the next link";
}

TEST_F(TrackerTest, RefusesMoreThan15RetriesAndOversizedRequests) {
    Outcome o;
    auto bad = tracker.submit(read_code, read_params, RequestTiming{100ms, 16}, o.callback(), t0);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(), make_error_code(ClientError::invalid_argument));
    std::vector<std::uint8_t> huge(max_parameter_size + 1);
    auto too_long = tracker.submit(write_code, huge, {}, o.callback(), t0);
    ASSERT_FALSE(too_long);
    EXPECT_EQ(too_long.error(), make_error_code(ClientError::request_too_long));
    std::vector<std::uint8_t> largest(max_parameter_size);
    EXPECT_TRUE(tracker.submit(write_code, largest, {}, o.callback(), t0));
    EXPECT_EQ(wire.frames.back().size(), max_frame_size);
    EXPECT_TRUE(wire.frames.size() == 1);
}

}  // namespace
