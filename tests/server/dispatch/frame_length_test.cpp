// The length stage of Dispatcher::handle (W342 5-1-3 1001, W596 1-2 2,012 bytes), on
// every route a frame can take: this node, a plant's router, the Host Link relay, a
// Serial Gateway port. 2,012 bytes go their way; 2,013 bytes are answered 1001 by the
// unit that received them, before any route copies them (under ASan a copy past a
// 2,012-byte buffer is a stack-buffer-overflow).
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/routing/router.hpp"
#include "server/serial/serial_ports.hpp"
#include "transport/asio.hpp"

namespace fins::server {
namespace {

constexpr std::size_t too_long = max_frame_size + 1;

// A request of exactly `size` bytes: header, command, then parameters (for 01 02 a D0
// write whose word count matches the data that fits).
std::vector<std::uint8_t> frame_of_size(std::size_t size, const NodeAddress& destination,
                                        CommandCode command = {0x01, 0x02}) {
    std::vector<std::uint8_t> frame(size, 0x00);
    const std::array<std::uint8_t, 12> head{
        0x80, 0x00, 0x02, destination.network, destination.node, destination.unit, 0x00,
        0x14, 0x00, 0x42, command.main,        command.sub};
    std::copy(head.begin(), head.end(), frame.begin());
    if (command == CommandCode{0x01, 0x02} && size >= 18) {
        const auto words = (size - 18) / 2;
        frame[12] = 0x82;
        frame[16] = static_cast<std::uint8_t>(words >> 8);
        frame[17] = static_cast<std::uint8_t>(words & 0xFF);
    }
    return frame;
}

std::uint16_t end_code_of(const std::array<std::uint8_t, max_frame_size>& out, std::size_t n) {
    return n >= 14 ? static_cast<std::uint16_t>(out[12] << 8 | out[13]) : 0xFFFF;
}

// Answers that come later (a serial port's) are kept here.
class KeptReplies final : public ReplyPath {
  public:
    KeptReplies() = default;
    KeptReplies(const KeptReplies&) = delete;
    KeptReplies& operator=(const KeptReplies&) = delete;
    ~KeptReplies() = default;
    Completion defer() override {
        return [this](Bytes frame) { answers.emplace_back(frame.begin(), frame.end()); };
    }
    std::vector<std::vector<std::uint8_t>> answers;
};

// One node (1.10) with a Serial Gateway port (unit 80) and a port whose Host Link
// slaves are FINS network 5 (unit 81, W342 5-1-1). The ports' devices do not exist: a
// request that reaches one is answered 0205 (serial_gateway_port.hpp).
struct GatewayNode {
    GatewayNode() {
        GatewayPortConfig gateway;
        gateway.name = "scu0.1";
        gateway.unit_address = 0x80;
        gateway.line.device = "/nonexistent/finskit-gateway";
        ports.add(std::make_shared<SerialGatewayPort>(io, gateway));
        GatewayPortConfig host_link = gateway;
        host_link.name = "scu0.2";
        host_link.unit_address = 0x81;
        host_link.network = 5;
        ports.add(std::make_shared<SerialGatewayPort>(io, host_link));
        dispatcher.attach_serial_ports(&ports);
        context.reply_path = &replies;
    }
    std::size_t handle(const std::vector<std::uint8_t>& frame) {
        return dispatcher.handle(frame, out, context);
    }

    asio::io_context io;
    plc::Plc plc;
    SerialPorts ports;
    Dispatcher dispatcher{plc, {1, 10, 0}};
    KeptReplies replies;
    RequestContext context{};
    std::array<std::uint8_t, max_frame_size> out{};
};

TEST(FrameLength, W342_5_1_3_ThisNodeServes2012BytesAndAnswers1001For2013) {
    GatewayNode node;
    auto n = node.handle(frame_of_size(max_frame_size, {1, 10, 0}));
    EXPECT_EQ(end_code_of(node.out, n), 0x0000);
    n = node.handle(frame_of_size(too_long, {1, 10, 0}));
    ASSERT_EQ(n, 14U);
    EXPECT_EQ(end_code_of(node.out, n), 0x1001);
    EXPECT_EQ(node.out[7], 10);  // from this node
}

// W342 5-1-1: a frame for a Host Link network goes to the relay, which copies it to
// re-address it. 2,012 bytes reach the relay (too long for a Host Link frame: 1001, the
// relay's own answer); 2,013 bytes never do: the relaying unit answers 1001 itself with
// the relay flag and its own address in the relay word (W342 5-1-3).
TEST(FrameLength, W342_5_1_3_TooLongForAHostLinkNetworkIsRefusedBeforeTheRelay) {
    GatewayNode node;
    auto n = node.handle(frame_of_size(max_frame_size, {5, 4, 0}));
    EXPECT_EQ(end_code_of(node.out, n), 0x1001);
    n = node.handle(frame_of_size(too_long, {5, 4, 0}));
    ASSERT_EQ(n, 16U);
    EXPECT_EQ(end_code_of(node.out, n), 0x9001);
    EXPECT_EQ(node.out[14], 1);   // relay word: this node's network
    EXPECT_EQ(node.out[15], 10);  // and node
    EXPECT_EQ(node.out[6], 5);    // the answer comes from the address asked
    EXPECT_EQ(node.out[7], 4);
    EXPECT_TRUE(node.replies.answers.empty());
}

// 28 04 to a gateway port (a unit of this node): 2,012 bytes are refused by the command
// (1001 above a Modbus-RTU frame), 2,013 by the length stage: plain 1001 either way.
TEST(FrameLength, W342_5_3_47_GatewayPortFramesOf2012And2013BytesAre1001) {
    GatewayNode node;
    for (const std::size_t size : {max_frame_size, too_long}) {
        const auto n = node.handle(frame_of_size(size, {1, 10, 0x80}, {0x28, 0x04}));
        EXPECT_EQ(end_code_of(node.out, n), 0x1001) << size;
    }
    EXPECT_TRUE(node.replies.answers.empty());
}

// W342 5-3-48 gives no limit of its own; the Modbus-ASCII frame does (Modbus over Serial
// Line 2.5.2.1: 513 characters, so 508 hex digits of address, function and data). Longer
// is "command too long" (W342 5-1-3 1001), whatever the digits are: the length is
// checked before the format (110C is for digits that give no LRC). 300 digits (more
// than 256 bytes of FINS data) are a valid frame and go to the line.
TEST(FrameLength, W342_5_3_48_ModbusAsciiLongerThan508DigitsIs1001NotAParameterError) {
    GatewayNode node;
    const auto send = [&](const std::vector<std::uint8_t>& digits) {
        auto frame = frame_of_size(12, {1, 10, 0x80}, {0x28, 0x05});
        frame.insert(frame.end(), digits.begin(), digits.end());
        const auto n = node.handle(frame);
        return n == 0 ? std::uint16_t{0} : end_code_of(node.out, n);
    };
    EXPECT_EQ(send(std::vector<std::uint8_t>(510, '1')), 0x1001);  // even, hex
    EXPECT_EQ(send(std::vector<std::uint8_t>(509, '1')), 0x1001);  // odd
    EXPECT_EQ(send(std::vector<std::uint8_t>(600, 'Z')), 0x1001);  // not hex
    EXPECT_EQ(send(std::vector<std::uint8_t>(9, '1')), 0x110C);    // odd, short
    EXPECT_EQ(send(std::vector<std::uint8_t>(300, '1')), 0);       // answered later
    ASSERT_EQ(node.replies.answers.size(), 1U);
    EXPECT_EQ(node.replies.answers.front()[12], 0x02);  // 0205: no device behind the port
    EXPECT_EQ(node.replies.answers.front()[13], 0x05);
}

// A router (CPU Unit A on networks 1 and 2) and the node behind it (CPU Unit B, 2.5):
// 2,012 bytes are relayed and written in B; 2,013 are answered 9001 by A, not copied.
TEST(FrameLength, W342_5_1_3_TooLongForAnotherNetworkIs1001FromTheRelayingUnitBeforeRouting) {
    plc::Plc a;
    plc::Plc b;
    Router router;
    const auto cpu_a = router.add_cpu(a, false);
    const auto cpu_b = router.add_cpu(b, false);
    const auto a1 = router.add_port(cpu_a, 0, {1, 1, 0});
    const auto a2 = router.add_port(cpu_a, 1, {2, 1, 0});
    const auto b2 = router.add_port(cpu_b, 0, {2, 5, 0});
    Dispatcher da1(a, {1, 1, 0});
    Dispatcher da2(a, {2, 1, 0});
    Dispatcher db2(b, {2, 5, 0});
    for (const auto& [port, d] : {std::pair{a1, &da1}, std::pair{a2, &da2}, std::pair{b2, &db2}}) {
        d->attach(router, port);
        router.set_dispatcher(port, *d);
    }
    plc::RoutingTables tables;
    tables.local[0] = {1, 0};
    tables.local[1] = {2, 1};
    tables.local_count = 2;
    plc::encode_routing_tables(tables, a.parameters().words(plc::routing_table_area));

    std::array<std::uint8_t, max_frame_size> out{};
    auto n = da1.handle(frame_of_size(max_frame_size, {2, 5, 0}), out, {});
    EXPECT_EQ(end_code_of(out, n), 0x0000);
    EXPECT_EQ(out[7], 5);  // B answered
    n = da1.handle(frame_of_size(too_long, {2, 5, 0}), out, {});
    ASSERT_EQ(n, 16U);
    EXPECT_EQ(end_code_of(out, n), 0x9001);
    EXPECT_EQ(out[14], 1);  // relay word: A's unit on network 1
    EXPECT_EQ(out[15], 1);
    // An answer that long is not passed on at all.
    auto answer = frame_of_size(too_long, {2, 5, 0});
    answer[0] = 0xC0;
    EXPECT_EQ(da1.handle(answer, out, {}), 0U);
}

}  // namespace
}  // namespace fins::server
