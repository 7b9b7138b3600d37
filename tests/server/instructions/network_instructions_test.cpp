// The Send/Rcv/SendCmd engine without sockets (W596 3): a fake transport records the
// frames, the test answers them; the io_context runs the timers and callbacks.
#include "server/instructions/network_instructions.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <vector>

#include "instruction_engine_fixture.hpp"

namespace fins::test {
namespace {

TEST_F(Engine, W596_3_SendWritesTheLocalWordsWith0102FromTheNodesOwnAddress) {
    auto dm = plc_.memory().words(Region::dm);
    dm[100] = 0x1234;
    dm[101] = 0xABCD;
    std::optional<InstructionResult> result;
    start(send(2), result);
    ASSERT_EQ(transport_.frames.size(), 1u);
    const auto& f = transport_.frames[0];
    const std::vector<std::uint8_t> expected{0x80, 0x00, 0x02, 0x00, 0x05, 0x00, 0x00, 0x01,
                                             0x00, f[9], 0x01, 0x02, 0x82, 0x00, 0xC8, 0x00,
                                             0x00, 0x02, 0x12, 0x34, 0xAB, 0xCD};
    EXPECT_EQ(f, expected);
    EXPECT_EQ(transport_.destinations[0], remote);
    EXPECT_TRUE(respond(answer(f, 0x0000)));
    wait(result);
    EXPECT_TRUE(result->done());
    EXPECT_EQ(result->port, 0);
    EXPECT_EQ(result->transmissions, 1u);
    EXPECT_EQ(result->end_code, 0x0000);
    EXPECT_EQ(engine_.in_flight(), 0u);
}

TEST_F(Engine, W596_3_RcvStoresTheAnswerInLocalMemory) {
    std::optional<InstructionResult> result;
    start(recv(2), result);
    ASSERT_EQ(transport_.frames.size(), 1u);
    const auto& f = transport_.frames[0];
    EXPECT_EQ(std::vector<std::uint8_t>(f.begin() + 10, f.end()),
              (std::vector<std::uint8_t>{0x01, 0x01, 0x82, 0x00, 0xC8, 0x00, 0x00, 0x02}));
    EXPECT_TRUE(respond(answer(f, 0x0000, {0x11, 0x22, 0x33, 0x44})));
    wait(result);
    EXPECT_TRUE(result->done());
    EXPECT_EQ(result->words, (std::vector<std::uint16_t>{0x1122, 0x3344}));
    EXPECT_EQ(plc_.memory().words(Region::dm)[300], 0x1122);
    EXPECT_EQ(plc_.memory().words(Region::dm)[301], 0x3344);
}

TEST_F(Engine, W596_3_SendCmdReturnsTheWholeAnswer) {
    std::optional<InstructionResult> result;
    InstructionRequest r = send(0);
    r.kind = InstructionKind::sendcmd;
    r.command = {0x05, 0x01};
    start(r, result);
    ASSERT_EQ(transport_.frames.size(), 1u);
    EXPECT_EQ(transport_.frames[0].size(), 12u);
    EXPECT_TRUE(respond(answer(transport_.frames[0], 0x0000, {0xAA, 0xBB})));
    wait(result);
    EXPECT_TRUE(result->done());
    EXPECT_EQ(result->response, (std::vector<std::uint8_t>{0x05, 0x01, 0x00, 0x00, 0xAA, 0xBB}));
}

TEST_F(Engine, W596_3_EndCodeOtherThanNormalIsErrorId0800WithTheEndCode) {
    std::optional<InstructionResult> result;
    start(recv(2), result);
    EXPECT_TRUE(respond(answer(transport_.frames[0], 0x1103)));
    wait(result);
    EXPECT_EQ(result->error_id, 0x0800);
    EXPECT_EQ(result->error_id_ex, 0x1103);
    EXPECT_EQ(plc_.memory().words(Region::dm)[300], 0);  // nothing stored
    // W342 5-1-3: 0040 is a normal completion at a CPU Unit with a non-fatal error.
    std::optional<InstructionResult> flagged;
    start(send(1), flagged);
    EXPECT_TRUE(respond(answer(transport_.frames[1], 0x0040)));
    wait(flagged);
    EXPECT_TRUE(flagged->done());
    EXPECT_EQ(flagged->end_code, 0x0040);
}

TEST_F(Engine, W596_3_TimeoutRetriesTheSameFrameThenEndsWith0205) {
    std::optional<InstructionResult> result;
    auto r = send(1);
    r.options.retries = 2;
    start(r, result);
    wait(result);
    EXPECT_EQ(result->error_id, 0x0800);
    EXPECT_EQ(result->error_id_ex, 0x0205);
    EXPECT_EQ(result->transmissions, 3u);
    ASSERT_EQ(transport_.frames.size(), 3u);
    EXPECT_EQ(transport_.frames[1], transport_.frames[0]);  // same SID
    EXPECT_EQ(transport_.frames[2], transport_.frames[0]);
    EXPECT_EQ(engine_.counters().timeouts, 1u);
    EXPECT_EQ(engine_.counters().retransmissions, 2u);
    // A late answer finds nobody waiting.
    EXPECT_FALSE(respond(answer(transport_.frames[0], 0x0000)));
}

TEST_F(Engine, W596_3_TimeoutZeroMeansTwoSeconds) {
    EXPECT_EQ(server::instruction_timeout(0), std::chrono::milliseconds(2000));
    EXPECT_EQ(server::instruction_timeout(1), std::chrono::milliseconds(100));
    EXPECT_EQ(server::instruction_timeout(65535), std::chrono::milliseconds(6553500));
}

TEST_F(Engine, W596_3_NoResponseSetsIcfBit0AndEndsDoneAfterSending) {
    std::optional<InstructionResult> result;
    auto r = send(1);
    r.options.no_response = true;
    start(r, result);
    wait(result);
    EXPECT_TRUE(result->done());
    ASSERT_EQ(transport_.frames.size(), 1u);
    EXPECT_EQ(transport_.frames[0][0], 0x81);
}

TEST_F(Engine, W596_3_TheThirtyThirdInstructionGets0104) {
    std::vector<std::optional<InstructionResult>> results(33);
    for (std::size_t i = 0; i < 33; ++i) {
        auto r = send(1);
        r.options.timeout = 600;
        start(r, results[i]);
    }
    EXPECT_EQ(engine_.in_flight(), 32u);
    EXPECT_FALSE(engine_.available());
    poll();
    ASSERT_TRUE(results[32].has_value());
    EXPECT_EQ(results[32]->error_id, 0x0800);
    EXPECT_EQ(results[32]->error_id_ex, 0x0104);
    EXPECT_EQ(transport_.frames.size(), 32u);
    // Every running instruction has its own SID.
    std::vector<int> seen(256, 0);
    for (const auto& f : transport_.frames)
        EXPECT_EQ(seen[f[9]]++, 0);
    // One ends: a port is free again.
    EXPECT_TRUE(respond(answer(transport_.frames[7], 0x0000)));
    poll();
    ASSERT_TRUE(results[7].has_value());
    EXPECT_EQ(results[7]->port, 7);
    EXPECT_TRUE(engine_.available());
    engine_.stop();
}

TEST_F(Engine, W596_3_ParameterErrorsAre0400AndSendNothing) {
    const auto expect_0400 = [&](InstructionRequest r, const char* what) {
        std::optional<InstructionResult> result;
        start(std::move(r), result);
        poll();
        ASSERT_TRUE(result.has_value()) << what;
        EXPECT_EQ(result->error_id, 0x0400) << what;
        EXPECT_EQ(result->port, -1) << what;
    };
    auto r = send(1);
    r.options.retries = 16;
    expect_0400(r, "retries 16");
    expect_0400(send(991), "991 words");
    r = recv(1);
    r.options.no_response = true;
    expect_0400(r, "Rcv without a response");
    r = recv(1);
    r.destination.node = 0xFF;
    expect_0400(r, "Rcv broadcast");
    r = send(1);
    r.remote = *parse_address("A448");
    expect_0400(r, "remote A area");
    r = send(1);
    r.local = *parse_address("D100.3");
    expect_0400(r, "bit address");
    r = send(2);
    r.local = *parse_address("D32767");
    expect_0400(r, "local words past the end");
    r = recv(1);
    r.local = *parse_address("A100");
    expect_0400(r, "Rcv into read-only A100");
    r = send(0);
    r.kind = InstructionKind::sendcmd;
    r.command = {0x05};
    expect_0400(r, "one-byte command");
    r.destination.network = 128;
    expect_0400(r, "network 128");
    EXPECT_TRUE(transport_.frames.empty());
}

TEST_F(Engine, W596_3_SizeZeroIsDoneWithoutSending) {
    std::optional<InstructionResult> result;
    start(send(0), result);
    wait(result);
    EXPECT_TRUE(result->done());
    EXPECT_TRUE(transport_.frames.empty());
}

TEST_F(Engine, AnswersFromAnotherNodeOrWithAnotherSidAreNotTaken) {
    std::optional<InstructionResult> result;
    start(send(1), result);
    auto other = answer(transport_.frames[0], 0);
    other[7] = 6;  // from node 6
    EXPECT_FALSE(respond(other));
    auto sid = answer(transport_.frames[0], 0);
    ++sid[9];
    EXPECT_FALSE(respond(sid));
    EXPECT_FALSE(respond(std::vector<std::uint8_t>{0xC0, 0x00}));
    EXPECT_EQ(engine_.counters().unmatched, 3u);
    EXPECT_TRUE(respond(answer(transport_.frames[0], 0)));
    wait(result);
}

// Issue 18 item 6: any local process can send a datagram to port 9600 and answer for a
// node. An answer counts only when it comes the way the command went (the node address
// table's address and port, or the command's FINS/TCP connection) and names the
// destination's network, node and unit: a forged one leaves the instruction waiting,
// and it ends with 0205 (W596 3: "the end code for the communication command").
TEST_F(Engine, Issue18_ForgedAnswersFromAnotherAddressPortOrConnectionAreIgnored) {
    std::optional<InstructionResult> result;
    start(send(1), result);
    const auto real = answer(transport_.frames[0], 0);
    const auto from = [&](const char* ip, std::uint16_t port, const void* connection) {
        server::InstructionRoute r{{asio::ip::make_address(ip), port}, connection, 0};
        return engine_.on_response(Bytes{real.data(), real.size()}, r);
    };
    EXPECT_FALSE(from("127.0.0.5", 9601, nullptr));   // another port of the right host
    EXPECT_FALSE(from("127.0.0.66", 9600, nullptr));  // another host
    int other_connection = 0;
    EXPECT_FALSE(from("127.0.0.5", 9600, &other_connection));  // a FINS/TCP connection
    auto network = real;
    network[6] = 0x03;  // SNA: another network
    EXPECT_FALSE(respond(network));
    auto unit = real;
    unit[8] = 0x10;  // SA2: a CPU Bus Unit, not the CPU Unit asked
    EXPECT_FALSE(respond(unit));
    auto to_other = real;
    to_other[4] = 0x09;  // DA1: another node
    EXPECT_FALSE(respond(to_other));
    EXPECT_EQ(engine_.counters().unmatched, 6u);
    wait(result);
    EXPECT_EQ(result->error_id, server::instruction_communications_error);
    EXPECT_EQ(result->error_id_ex, 0x0205);

    // The same answer the right way completes the next instruction.
    result.reset();
    start(send(1), result);
    EXPECT_TRUE(respond(answer(transport_.frames[1], 0)));
    wait(result);
    EXPECT_TRUE(result->done()) << result->detail;
}

// W596 3 (Send error g, Rcv j, SendCmd h): "FINS/TCP connection has not been
// established" ends the instruction at once: ErrorID 0800, ErrorIDEx 0101 (W342 5-1-3
// "Local node not in network": the node's end of that connection is not up).
TEST_F(Engine, W596_3_FinsTcpConnectionNotEstablishedIs0800With0101) {
    std::optional<InstructionResult> result;
    transport_.answer = InstructionTransport::Sent::not_established;
    start(send(1), result);
    wait(result);
    EXPECT_EQ(result->error_id, server::instruction_communications_error);
    EXPECT_EQ(result->error_id_ex, 0x0101);
    EXPECT_EQ(result->transmissions, 1u);
    EXPECT_NE(result->detail.find("not established"), std::string::npos) << result->detail;
}

TEST_F(Engine, NoRouteAndFailedSendsEndWithTheirEndCodes) {
    std::optional<InstructionResult> result;
    transport_.answer = InstructionTransport::Sent::no_route;
    start(send(1), result);
    wait(result);
    EXPECT_EQ(result->error_id_ex, 0x0501);
    result.reset();
    transport_.answer = InstructionTransport::Sent::failed;
    start(send(1), result);
    wait(result);
    EXPECT_EQ(result->error_id_ex, 0x0103);
    result.reset();
    transport_.answer = InstructionTransport::Sent::no_port;
    start(send(1), result);
    wait(result);
    EXPECT_EQ(result->error_id_ex, 0x0101);
}

// CS/CJ CPU Units show their network instruction ports in the Auxiliary Area: A202
// Port Enabled Flags (ON = free), A203-A210 Completion Codes, A219 Port Error Flags.
TEST_F(Engine, CsCjPortFlagsA202A203A219FollowTheInstruction) {
    EXPECT_EQ(a(202), 0x00FF);
    std::optional<InstructionResult> result;
    start(send(1), result);
    EXPECT_EQ(a(202), 0x00FE);  // port 0 busy
    wait(result);               // no answer: 0205
    EXPECT_EQ(a(202), 0x00FF);
    EXPECT_EQ(a(203), 0x0205);
    EXPECT_EQ(a(219), 0x0001);
    result.reset();
    start(send(1), result);
    EXPECT_TRUE(respond(answer(transport_.frames[1], 0)));
    wait(result);
    EXPECT_EQ(a(203), 0x0000);
    EXPECT_EQ(a(219), 0x0000);
}

class NxEngine : public Engine {
  protected:
    NxEngine() : Engine(*plc::find_profile("nx102")) {}
};

TEST_F(NxEngine, NxHasNoAuxiliaryAreaFlags) {
    EXPECT_TRUE(plc_.memory().words(Region::auxiliary).empty());
    std::optional<InstructionResult> result;
    start(send(1), result);
    wait(result);
    EXPECT_EQ(result->error_id_ex, 0x0205);
}

TEST(InstructionText, DestinationsAndKinds) {
    EXPECT_EQ(server::parse_destination("1.5.0"), (NodeAddress{1, 5, 0}));
    EXPECT_EQ(server::parse_destination("0.5"), (NodeAddress{0, 5, 0}));
    EXPECT_EQ(server::parse_destination("0.5.0x10"), (NodeAddress{0, 5, 0x10}));
    EXPECT_FALSE(server::parse_destination("128.5.0"));
    EXPECT_FALSE(server::parse_destination("0.256.0"));
    EXPECT_FALSE(server::parse_destination("0.5.0.1"));
    EXPECT_FALSE(server::parse_destination("5"));
    EXPECT_FALSE(server::parse_destination("a.b.c"));
    EXPECT_EQ(server::parse_instruction_kind("rcv"), InstructionKind::recv);
    EXPECT_FALSE(server::parse_instruction_kind("read"));
}

}  // namespace
}  // namespace fins::test
