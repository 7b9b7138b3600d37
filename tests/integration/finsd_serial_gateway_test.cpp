// finsd with Serial Gateway ports from the command line (--serial scuN.P=DEVICE /
// board.P=DEVICE, mode gateway): 05 02 lists the Serial Communications Unit, 28 03
// reaches the simulated CompoWay/F controller over UDP and over FINS/TCP (the deferred
// answer of both sessions), and a unit number that clashes is a clear start-up error.
#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "fins/client.hpp"
#include "integration/finsd_run.hpp"
#include "integration/process.hpp"
#include "integration/pty_pair.hpp"

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

TEST(FinsdSerialGateway, MissingDeviceIsAClearStartError) {
    Finsd finsd({"--serial", "scu2.1=/nonexistent/tty"});
    EXPECT_FALSE(finsd.started());
    EXPECT_EQ(finsd.result().exit_code, 3);
    EXPECT_NE(finsd.result().err.find("scu2.1"), std::string::npos) << finsd.result().err;
}

}  // namespace
}  // namespace fins::test
