// finsd's instructions and the request engine's service-ID rule (engine/sid_pool.hpp,
// W596 3 Option.Retry): a retry is the same frame, a timed-out SID is quarantined, and
// frames that ask for no answer use none up.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>

#include "instruction_engine_fixture.hpp"

namespace fins::test {
namespace {

// W596 3 Send/Rcv/SendCmd "Option" (Retry): a retry is the identical frame, SID included,
// so the answer to the first transmission, arriving after the retry went out, completes
// the instruction (the rule of fins::Client, engine/request_tracker.hpp).
TEST_F(Engine, W596_3_RetryResendsTheSameSidAndAnAnswerToTheFirstTransmissionCompletes) {
    std::optional<InstructionResult> result;
    auto r = send(1);
    r.options.retries = 3;
    start(r, result);
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (transport_.frames.size() < 2 && std::chrono::steady_clock::now() < end) {
        io_.restart();
        io_.run_for(std::chrono::milliseconds(20));
    }
    ASSERT_GE(transport_.frames.size(), 2u);
    EXPECT_EQ(transport_.frames[1][9], transport_.frames[0][9]);
    EXPECT_EQ(transport_.frames[1], transport_.frames[0]);
    EXPECT_TRUE(respond(answer(transport_.frames[0], 0x0000)));
    wait(result);
    EXPECT_TRUE(result->done());
    EXPECT_EQ(result->transmissions, transport_.frames.size());
}

// W596 3 (Retry) with the engine's SID rule (engine/sid_pool.hpp): the SID of an
// instruction that timed out is quarantined. Before, SIDs went round 01..FF, so the 256th
// instruction after one that timed out got its SID again and the late answer to the old
// one completed it with the old command's result.
TEST_F(Engine, W596_3_LateAnswerToATimedOutInstructionDoesNotCompleteALaterOne) {
    std::optional<InstructionResult> lost;
    start(send(1), lost);
    wait(lost);
    ASSERT_EQ(lost->error_id_ex, 0x0205);
    const auto late = answer(transport_.frames[0], 0x0000);
    // 255 instructions answered at once, then one left waiting.
    for (int i = 0; i < 255; ++i) {
        std::optional<InstructionResult> quick;
        start(send(1), quick);
        ASSERT_TRUE(respond(answer(transport_.frames.back(), 0x0000)));
        poll();
        ASSERT_TRUE(quick.has_value());
        ASSERT_TRUE(quick->done());
    }
    std::optional<InstructionResult> waiting;
    auto r = send(1);
    r.options.timeout = 600;
    start(r, waiting);
    EXPECT_NE(transport_.frames.back()[9], transport_.frames[0][9]);
    EXPECT_FALSE(respond(late));
    poll();
    EXPECT_FALSE(waiting.has_value());
    EXPECT_EQ(engine_.in_flight(), 1u);
    engine_.stop();
}

// Issue 27: the instructions run on the client's tracker, which tells the transport of
// every transmission that went unanswered (a FINS/TCP client connection counts them),
// retries included, and of none that was answered.
TEST_F(Engine, Issue27_TheTransportHearsOfEveryUnansweredTransmission) {
    std::optional<InstructionResult> result;
    auto r = send(1);
    r.options.retries = 2;
    start(r, result);
    wait(result);
    EXPECT_EQ(result->error_id_ex, 0x0205);
    ASSERT_EQ(transport_.unanswered_routes.size(), 3u);
    for (const auto& way : transport_.unanswered_routes)
        EXPECT_TRUE(way.same_way(transport_.route));
    result.reset();
    start(send(1), result);
    EXPECT_TRUE(respond(answer(transport_.frames.back(), 0x0000)));
    wait(result);
    EXPECT_TRUE(result->done());
    EXPECT_EQ(transport_.unanswered_routes.size(), 3u);
}

// Issue 27: a frame the transport refuses never left, so nothing can answer it late: its
// SID is not quarantined and is the next instruction's again (before, it was
// quarantined like a timed-out one).
TEST_F(Engine, Issue27_ARefusedFrameDoesNotQuarantineItsSid) {
    std::optional<InstructionResult> result;
    transport_.answer = InstructionTransport::Sent::no_route;
    auto r = send(1);
    r.options.timeout = 600;  // a quarantine would last 120 s
    start(r, result);
    wait(result);
    EXPECT_EQ(result->error_id_ex, 0x0501);
    const auto refused_sid = transport_.frames[0][9];
    transport_.answer = InstructionTransport::Sent::ok;
    // Every other SID once (answered at once), then the refused one comes round again.
    bool again = false;
    for (int i = 0; i < 256 && !again; ++i) {
        std::optional<InstructionResult> quick;
        start(send(1), quick);
        again = transport_.frames.back()[9] == refused_sid;
        ASSERT_TRUE(respond(answer(transport_.frames.back(), 0x0000)));
        poll();
        ASSERT_TRUE(quick.has_value());
    }
    EXPECT_TRUE(again);
}

// W596 3 (no-response mode): nothing answers such a frame, so its SID is not quarantined;
// a schedule sending many of them never runs out of SIDs.
TEST_F(Engine, W596_3_NoResponseFramesDoNotUseUpServiceIds) {
    for (int i = 0; i < 600; ++i) {
        std::optional<InstructionResult> result;
        auto r = send(1);
        r.options.no_response = true;
        start(r, result);
        poll();
        ASSERT_TRUE(result.has_value());
        ASSERT_TRUE(result->done()) << i << ": " << result->detail;
    }
}

}  // namespace
}  // namespace fins::test
