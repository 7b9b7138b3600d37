// finsd with Serial Gateway ports from the command line (--serial scuN.P=DEVICE /
// board.P=DEVICE, mode gateway): 05 02 lists the Serial Communications Unit, 28 03
// reaches the simulated CompoWay/F controller over UDP and over FINS/TCP (the deferred
// answer of both sessions), and a unit number that clashes is a clear start-up error.
#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "fins/client.hpp"
#include "integration/support/finsd_process.hpp"
#include "integration/support/process.hpp"
#include "integration/support/pty_pair.hpp"

namespace fins::test {
namespace {

const std::string sim_path = std::string(FINS_BIN_DIR) + "/fins_compowayf_sim";

std::vector<std::uint8_t> ascii(std::string_view s) {
    return {s.begin(), s.end()};
}

std::unique_ptr<Client> client_to(const Finsd& finsd, std::uint8_t unit, bool tcp) {
    ClientOptions o;
    o.port = finsd.port();
    o.protocol = tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
    o.destination.unit = unit;
    o.timeout = std::chrono::milliseconds(5000);
    auto c = Client::connect(o);
    EXPECT_TRUE(c.has_value()) << (c ? "" : c.error().message());
    return c ? std::move(*c) : nullptr;
}

TEST(FinsdSerialGateway, W342_5_3_46_CompowayFOverUdpAndTcpAnd0502ListsTheUnit) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Child sim({sim_path, line.b()});
    ASSERT_EQ(sim.read_line(), "ready");
    Finsd finsd({"--serial", "scu1.2=" + line.a() + ",mode=gateway,baud=38400,timeout=2"});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;

    for (const bool tcp : {false, true}) {
        auto c = client_to(finsd, 0x85, tcp);  // unit 1, port 2: 81 + 4
        ASSERT_TRUE(c);
        const auto params = ascii(
            "01000"
            "0101"
            "C00000000001");
        const auto r = c->send_raw(CommandCode{0x28, 0x03}, params);
        ASSERT_TRUE(r.has_value()) << (tcp ? "tcp: " : "udp: ") << r.error().message();
        EXPECT_EQ(r->code.raw(), 0x0000);
        EXPECT_EQ(std::string(r->data.begin(), r->data.end()),
                  "0100"
                  "00"
                  "0101"
                  "0000"
                  "00000019");
    }

    // 05 02 from unit 00: the CPU Unit, the built-in EtherNet/IP unit (10) and the
    // Serial Communications Unit with unit number 1 (11).
    auto cpu = finsd.client();
    const auto units = cpu->send_raw(CommandCode{0x05, 0x02}, std::vector<std::uint8_t>{0x00});
    ASSERT_TRUE(units.has_value());
    const std::string listing(units->data.begin(), units->data.end());
    EXPECT_NE(listing.find("\x11"
                           "CJ1W-SCU41-V1"),
              std::string::npos);
}

TEST(FinsdSerialGateway, UnitNumberOfTheEthernetUnitIsRefusedAtStart) {
    // cj2h's built-in EtherNet/IP port is CPU Bus Unit 0 (unit address 10).
    Finsd finsd({"--serial", "scu0.1=/dev/null"});
    EXPECT_FALSE(finsd.started());
    EXPECT_EQ(finsd.result().exit_code, 2);
    EXPECT_NE(finsd.result().err.find("unit address 10"), std::string::npos) << finsd.result().err;
}

// finsd keeps serving (as with a Host Link port): the port answers 0205 while its device
// cannot be opened (W336 11-3-2: a send that cannot start is a 0205-class failure).
TEST(FinsdSerialGateway, MissingDeviceAnswers0205AndFinsdKeepsServing) {
    Finsd finsd({"--serial", "scu2.1=/nonexistent/tty,timeout=0.5"});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    auto port = client_to(finsd, 0x88, false);  // unit 2, port 1
    const auto r = port->send_raw(CommandCode{0x28, 0x03}, ascii("01000"
                                                                 "0601"));
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->code.raw(), 0x0205);
    EXPECT_EQ(words_of(*finsd.client(), "D0", 1).size(), 1U);
}

}  // namespace
}  // namespace fins::test

namespace fins::test {
namespace {

// W342 5-1-1 "Specifying the Destination PLC's FINS Address", without a routing table:
// DNA = the serial port's unit address (84: unit 1, port 1), DA1 = Host Link unit
// number + 1, DA2 = a unit of the PLC behind the port (00, its CPU Unit). Client ->
// UDP -> finsd A (gateway port scu1.1) -> socat pty pair -> finsd B (--serial cpu=...,
// Host Link unit 3) -> the answer back, with a write and a read checked on both sides.
TEST(FinsdSerialGateway, W342_5_1_1_HostLinkFinsThroughTheGatewayEndToEnd) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Finsd plc_b({"--serial", "cpu=" + line.b() + ",unit=3"});
    ASSERT_TRUE(plc_b.started()) << plc_b.result().err;
    Finsd gateway_a({"--serial", "scu1.1=" + line.a() + ",timeout=3"});
    ASSERT_TRUE(gateway_a.started()) << gateway_a.result().err;

    ClientOptions o;
    o.port = gateway_a.port();
    o.destination = NodeAddress{0x84, 3 + 1, 0x00};
    o.timeout = std::chrono::milliseconds(5000);
    auto through = Client::connect(o);
    ASSERT_TRUE(through.has_value()) << through.error().message();

    const std::vector<std::uint16_t> values{0x1234, 0xBEEF};
    const auto written = (*through)->write_words(addr("D100"), values);
    ASSERT_TRUE(written.has_value()) << written.error().message();
    const auto read = (*through)->read_words(addr("D100"), 2);
    ASSERT_TRUE(read.has_value()) << read.error().message();
    EXPECT_EQ(*read, values);
    // The write landed in PLC B, not in the gateway's own CPU Unit.
    EXPECT_EQ(words_of(*plc_b.client(), "D100", 2), values);
    EXPECT_EQ(words_of(*gateway_a.client(), "D100", 2), (std::vector<std::uint16_t>{0, 0}));

    // DA1 beyond Host Link unit 31 + 1: no such node behind the port.
    o.destination = NodeAddress{0x84, 40, 0x00};
    auto nowhere = Client::connect(o);
    ASSERT_TRUE(nowhere.has_value());
    EXPECT_EQ(end_code(**nowhere, CommandCode{0x01, 0x01}, {0x82, 0, 100, 0, 0, 1}), 0x0201U);
}

// network= gives the serial path a FINS network number of its own (W342 5-1-1: with a
// routing table the destination is that network); the unit address no longer is one.
TEST(FinsdSerialGateway, W342_5_1_1_NetworkKeyNamesThePlcsBehindThePort) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Finsd plc_b({"--serial", "cpu=" + line.b() + ",unit=3"});
    ASSERT_TRUE(plc_b.started()) << plc_b.result().err;
    Finsd gateway_a({"--serial", "scu1.1=" + line.a() + ",timeout=3,network=5"});
    ASSERT_TRUE(gateway_a.started()) << gateway_a.result().err;
    ClientOptions o;
    o.port = gateway_a.port();
    o.destination = NodeAddress{5, 3 + 1, 0x00};
    o.timeout = std::chrono::milliseconds(5000);
    auto through = Client::connect(o);
    ASSERT_TRUE(through.has_value()) << through.error().message();
    const std::vector<std::uint16_t> values{0x0505};
    ASSERT_TRUE((*through)->write_words(addr("D7"), values).has_value());
    EXPECT_EQ(words_of(*plc_b.client(), "D7", 1), values);
    // DNA 84 (the unit address) is not a way to it any more: a network this node does
    // not reach answers 0201, as any other.
    o.destination = NodeAddress{0x84, 3 + 1, 0x00};
    auto old_way = Client::connect(o);
    ASSERT_TRUE(old_way.has_value());
    EXPECT_EQ(end_code(**old_way, CommandCode{0x01, 0x01}, {0x82, 0, 7, 0, 0, 1}), 0x0201U);
}

}  // namespace
}  // namespace fins::test

namespace fins::test {
namespace {

// The config file's [serial] table configures a gateway port the same way (a board port
// on a CS-series profile here: unit addresses E4/E5, the Inner Board E1 in 05 02).
TEST(FinsdSerialGateway, ConfigFileSerialTableBoardPortOnACsProfile) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Child sim({sim_path, line.b(), "--node", "7"});
    ASSERT_EQ(sim.read_line(), "ready");
    ScratchDir dir("gateway-config");
    const auto file = dir.write("finsd.toml", "profile = \"cs1h\"\n[serial]\n\"board.1\" = \"" +
                                                  line.a() + ",timeout=2\"\n");
    Finsd finsd({"--config", file});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    auto board = client_to(finsd, 0xE4, false);
    const auto r = board->send_raw(CommandCode{0x28, 0x03}, ascii("07000"
                                                                  "0503"));
    ASSERT_TRUE(r.has_value()) << r.error().message();
    EXPECT_EQ(std::string(r->data.begin(), r->data.end()),
              "0700"
              "00"
              "0503"
              "0000"
              "E5CC-SIM  00D9");
    const auto units =
        finsd.client()->send_raw(CommandCode{0x05, 0x02}, std::vector<std::uint8_t>{0x00});
    ASSERT_TRUE(units.has_value());
    const std::string listing(units->data.begin(), units->data.end());
    EXPECT_NE(listing.find("\xE1"
                           "CS1W-SCB41-V1"),
              std::string::npos);
}

}  // namespace
}  // namespace fins::test
