// The poller's pure parts, driven by an invented clock (no sockets, no sleeping): the
// drift-free tick grid and its overrun count, the start phases, the back-off with full
// jitter, and the in-flight window's answer matching (poll_schedule.hpp,
// request_window.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "bridge/poll_schedule.hpp"
#include "bridge/request_window.hpp"
#include "fins/commands/memory_area.hpp"

namespace fins::bridge {
namespace {

using namespace std::chrono_literals;
using Clock = PollClock;

// An invented time far from the clock's epoch.
const Clock::time_point t0 = Clock::time_point{} + 1000h;

TEST(PollerTickGrid, StaysOnItsGridHoweverLateEachTickRuns) {
    TickGrid grid(t0, 100ms, 0.25);
    EXPECT_EQ(grid.next(), t0 + 25ms);
    // Each tick runs up to 99 ms late (a busy loop): the grid does not move.
    for (int k = 0; k < 1000; ++k) {
        const auto late = std::chrono::milliseconds((k * 37) % 100);
        EXPECT_EQ(grid.advance(grid.next() + late), 0u) << k;
        EXPECT_EQ(grid.next(), t0 + 25ms + (k + 1) * 100ms) << k;
    }
}

TEST(PollerTickGrid, SkipsAndCountsTheGridPointsItWasTooLateFor) {
    TickGrid grid(t0, 100ms, 0.0);
    // The tick due at t0 runs at t0 + 250 ms: t0 + 100 and t0 + 200 are missed.
    EXPECT_EQ(grid.advance(t0 + 250ms), 2u);
    EXPECT_EQ(grid.next(), t0 + 300ms);
    // Exactly on the next grid point is not late: the one after it is next.
    EXPECT_EQ(grid.advance(t0 + 300ms), 0u);
    EXPECT_EQ(grid.next(), t0 + 400ms);
    // Running exactly when the following point is due misses that point.
    EXPECT_EQ(grid.advance(t0 + 500ms), 1u);
    EXPECT_EQ(grid.next(), t0 + 600ms);
}

TEST(PollerPhases, SpreadEvenlyOverTheIntervalForAnyCount) {
    for (std::size_t n : {2u, 3u, 10u, 100u, 1000u}) {
        std::vector<double> phases;
        for (std::size_t i = 0; i < n; ++i) {
            const double p = spread_phase(i);
            ASSERT_GE(p, 0.0);
            ASSERT_LT(p, 1.0);
            phases.push_back(p);
        }
        std::sort(phases.begin(), phases.end());
        double widest = 1.0 - phases.back() + phases.front();  // around the end
        for (std::size_t i = 1; i < n; ++i)
            widest = std::max(widest, phases[i] - phases[i - 1]);
        // Three-distance theorem: golden-ratio gaps are within a factor ~2.6 of 1/n.
        EXPECT_LT(widest, 2.7 / static_cast<double>(n)) << n;
    }
}

TEST(PollerBackoff, CapDoublesFromTheMinimumUpToTheMaximum) {
    Backoff b(500ms, 30000ms, 1);
    EXPECT_EQ(b.cap(0), 500ms);
    EXPECT_EQ(b.cap(1), 1000ms);
    EXPECT_EQ(b.cap(5), 16000ms);
    EXPECT_EQ(b.cap(6), 30000ms);
    EXPECT_EQ(b.cap(1000), 30000ms);
}

TEST(PollerBackoff, FullJitterSpreadsEachWaitOverZeroToTheCap) {
    // A thousand PLCs failing at once: their first retries spread over [0, 500 ms).
    std::vector<std::int64_t> first;
    for (std::uint64_t seed = 0; seed < 1000; ++seed) {
        Backoff b(500ms, 30000ms, seed);
        first.push_back(b.next().count());
        for (unsigned n = 1; n < 10; ++n) {
            const auto wait = b.next();
            EXPECT_GE(wait.count(), 0);
            EXPECT_LE(wait, b.cap(n));
        }
        EXPECT_EQ(b.attempt(), 10u);
        b.reset();
        EXPECT_EQ(b.attempt(), 0u);
        EXPECT_LE(b.next(), 500ms);
    }
    std::sort(first.begin(), first.end());
    EXPECT_GE(first.front(), 0);
    EXPECT_LT(first.back(), 500);
    // Uniform: each 100 ms tenth holds 20 % +- a margin, none is a crowd.
    for (std::int64_t from = 0; from < 500; from += 100) {
        const auto in = std::count_if(first.begin(), first.end(),
                                      [&](auto w) { return w >= from && w < from + 100; });
        EXPECT_GT(in, 130) << from;
        EXPECT_LT(in, 270) << from;
    }
}

constexpr std::uint8_t plc_node = 7;

Header answer_header(std::uint8_t sid, std::uint8_t node = plc_node) {
    Header h;
    h.source = {0, node, 0};
    h.destination = {0, 254, 0};
    h.service_id = sid;
    return h;
}

Request sent(RequestWindow& w, Clock::time_point now, std::size_t frame,
             CommandCode command = MemoryAreaRead::code) {
    Request r;
    r.frame = frame;
    r.command = command;
    r.service_id = w.allocate(now);
    r.deadline = now + 1s;
    w.add(r);
    return r;
}

TEST(PollerWindow, MatchesAnAnswerBySidSourceNodeAndCommandOnly) {
    RequestWindow w(4, 2s);
    const auto a = sent(w, t0, 0);
    const auto b = sent(w, t0, 1, MultipleMemoryAreaRead::code);
    EXPECT_NE(a.service_id, b.service_id);
    EXPECT_EQ(w.size(), 2u);
    // Another node, or another command, with a's SID: not a's answer.
    EXPECT_FALSE(w.take_answer(answer_header(a.service_id, 9), MemoryAreaRead::code, plc_node, t0));
    EXPECT_FALSE(
        w.take_answer(answer_header(a.service_id), MultipleMemoryAreaRead::code, plc_node, t0));
    EXPECT_FALSE(w.take_answer(answer_header(static_cast<std::uint8_t>(b.service_id + 1)),
                               MemoryAreaRead::code, plc_node, t0));
    auto got =
        w.take_answer(answer_header(b.service_id), MultipleMemoryAreaRead::code, plc_node, t0);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->frame, 1u);
    // The same answer again (a duplicated datagram) finds nothing.
    EXPECT_FALSE(
        w.take_answer(answer_header(b.service_id), MultipleMemoryAreaRead::code, plc_node, t0));
    got = w.take_answer(answer_header(a.service_id), MemoryAreaRead::code, plc_node, t0);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->frame, 0u);
    EXPECT_TRUE(w.empty());
}

// The answer a PLC gives under another node than the one addressed: refused as every
// answer not ours, and recognised, so the poller can say what to configure.
TEST(PollerWindow, TellsAnAnswerFromAnotherNodeToAFrameInFlight) {
    RequestWindow w(4, 2s);
    const auto a = sent(w, t0, 0);
    const auto other = answer_header(a.service_id, 12);
    EXPECT_TRUE(w.from_other_node(other, MemoryAreaRead::code, plc_node));
    EXPECT_FALSE(w.take_answer(other, MemoryAreaRead::code, plc_node, t0));
    EXPECT_EQ(w.size(), 1u);  // still in flight: it times out
    // Not from another node: the right node, another command, a SID not in flight.
    EXPECT_FALSE(w.from_other_node(answer_header(a.service_id), MemoryAreaRead::code, plc_node));
    EXPECT_FALSE(w.from_other_node(other, MultipleMemoryAreaRead::code, plc_node));
    EXPECT_FALSE(w.from_other_node(answer_header(static_cast<std::uint8_t>(a.service_id + 1), 12),
                                   MemoryAreaRead::code, plc_node));
    ASSERT_TRUE(w.take_answer(answer_header(a.service_id), MemoryAreaRead::code, plc_node, t0));
    // Answered (quarantined): a late copy from another node is nothing to report.
    EXPECT_FALSE(w.from_other_node(other, MemoryAreaRead::code, plc_node));
}

TEST(PollerWindow, ALateAnswerAfterAResendNeverCompletesAnotherRequest) {
    RequestWindow w(4, 2s);
    const auto first = sent(w, t0, 0);
    // No answer within the timeout: the frame is taken out and resent with a new SID.
    std::vector<Request> expired;
    w.take_expired(t0 + 999ms, expired);
    EXPECT_TRUE(expired.empty());
    w.take_expired(t0 + 1s, expired);
    ASSERT_EQ(expired.size(), 1u);
    const auto resent = sent(w, t0 + 1s, 0);
    EXPECT_NE(resent.service_id, first.service_id);
    // The late answer to the first send arrives: nothing in flight has its SID.
    EXPECT_FALSE(w.take_answer(answer_header(first.service_id), MemoryAreaRead::code, plc_node,
                               t0 + 1100ms));
    EXPECT_TRUE(w.take_answer(answer_header(resent.service_id), MemoryAreaRead::code, plc_node,
                              t0 + 1200ms));
    // Hundreds of frames within the quarantine (SIDs wrap around): none gets the first SID,
    // so its answer arriving even later still finds nothing.
    auto now = t0 + 1200ms;
    for (int i = 0; i < 600; ++i) {
        now += 1ms;
        const auto r = sent(w, now, 1);
        ASSERT_NE(r.service_id, first.service_id) << i;
        ASSERT_TRUE(
            w.take_answer(answer_header(r.service_id), MemoryAreaRead::code, plc_node, now));
        ASSERT_FALSE(
            w.take_answer(answer_header(first.service_id), MemoryAreaRead::code, plc_node, now));
    }
}

TEST(PollerWindow, SidsAreReusedAfterTheQuarantineAndNeverWhileInFlight) {
    RequestWindow w(64, 2s);
    std::set<std::uint8_t> in_flight;
    for (int i = 0; i < 64; ++i)
        EXPECT_TRUE(in_flight.insert(sent(w, t0, 0).service_id).second);
    EXPECT_TRUE(w.full());
    std::vector<Request> all;
    w.take_all(t0, all);
    EXPECT_EQ(all.size(), 64u);
    EXPECT_TRUE(w.empty());
    // The 192 never used go first; then, within the quarantine, the oldest released ones.
    std::set<std::uint8_t> next;
    for (int i = 0; i < 192; ++i) {
        const auto r = sent(w, t0 + 1s, 0);
        EXPECT_FALSE(in_flight.contains(r.service_id));
        next.insert(r.service_id);
        ASSERT_TRUE(
            w.take_answer(answer_header(r.service_id), MemoryAreaRead::code, plc_node, t0 + 1s));
    }
    EXPECT_EQ(next.size(), 192u);
    // After the quarantine every SID may be used again.
    const auto r = sent(w, t0 + 10s, 0);
    EXPECT_TRUE(in_flight.contains(r.service_id));
}

TEST(PollerWindow, TheEarliestDeadlineIsTheOneToWaitFor) {
    RequestWindow w(4, 2s);
    EXPECT_FALSE(w.earliest_deadline());
    Request r;
    r.command = MemoryAreaRead::code;
    r.service_id = w.allocate(t0);
    r.deadline = t0 + 3s;
    w.add(r);
    r.service_id = w.allocate(t0);
    r.deadline = t0 + 1s;
    w.add(r);
    EXPECT_EQ(w.earliest_deadline(), t0 + 1s);
    Request hs{Request::Kind::handshake};
    hs.deadline = t0 + 500ms;
    w.add(hs);
    EXPECT_EQ(w.earliest_deadline(), t0 + 500ms);
    // The handshake is never an answer's match, whatever SID the answer carries.
    EXPECT_FALSE(w.take_answer(answer_header(0), CommandCode{}, plc_node, t0));
    w.remove_handshake();
    EXPECT_EQ(w.size(), 2u);
    EXPECT_EQ(w.earliest_deadline(), t0 + 1s);
}

}  // namespace
}  // namespace fins::bridge
