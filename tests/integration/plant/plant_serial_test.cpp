// Each [[plc]] takes serial ports of its own ([plc.serial]; README "A plant of several
// networks"), as [serial] gives a single node: a Host Link slave port answering for that
// CPU Unit, and Serial Gateway ports on a Serial Communications Unit mounted in it only.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fins/address.hpp"
#include "integration/support/finsd_process.hpp"
#include "integration/support/pty_pair.hpp"

namespace fins::test {
namespace {

// line-a (1.1) and line-b (2.1), each with its own D100; `a_extra` and `b_extra` are
// more tables of each.
std::string plant(const std::string& a_extra, const std::string& b_extra = "") {
    return R"(
[[plc]]
name = "line-a"
memory = { "D100" = [11, 12] }
)" + a_extra +
           R"(
  [[plc.ethernet]]
  network = 1
  bind = "127.0.72.1"
  port = 9611
[[plc]]
name = "line-b"
memory = { "D100" = [21, 22] }
)" + b_extra +
           R"(
  [[plc.ethernet]]
  network = 2
  bind = "127.0.73.1"
  port = 9611
)";
}

std::unique_ptr<Client> client_to(const std::string& host, NodeAddress destination) {
    ClientOptions o;
    o.host = host;
    o.port = 9611;
    o.destination = destination;
    o.timeout = std::chrono::milliseconds(3000);
    auto c = Client::connect(o);
    EXPECT_TRUE(c) << c.error().message();
    return c ? std::move(*c) : nullptr;
}

TEST(PlantSerial, W342_3_5_HostLinkPortAnswersForItsOwnCpuUnit) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    PtyPair pty;
    ASSERT_TRUE(pty.ok());
    ScratchDir dir("plant-hostlink");
    const auto serial = "  [plc.serial]\n  cpu = \"" + pty.a() + "\"\n";
    Finsd d({"--config", dir.write("plant.toml", plant("", serial))});
    ASSERT_TRUE(d.started()) << d.result().err;
    ClientOptions o;
    o.protocol = ClientOptions::Protocol::serial;
    o.serial.device = pty.b();
    o.timeout = std::chrono::milliseconds(3000);
    auto c = Client::connect(o);
    ASSERT_TRUE(c) << c.error().message();
    const auto got = (*c)->read_words(*parse_address("D100"), 2);
    ASSERT_TRUE(got) << got.error().message();
    EXPECT_EQ(*got, (std::vector<std::uint16_t>{21, 22}));  // line-b's, not line-a's
}

// W342 5-3-46 (28 03) on a gateway port whose device cannot be opened: 0205, as for a
// single node; the unit is listed by 05 02 of its CPU Unit only.
TEST(PlantSerial, W342_5_3_46_GatewayPortIsOnItsOwnCpuUnit) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-gateway");
    const auto serial = "  [plc.serial]\n  \"scu2.1\" = \"/nonexistent/tty,timeout=0.5\"\n";
    Finsd d({"--config", dir.write("plant.toml", plant(serial))});
    ASSERT_TRUE(d.started()) << d.result().err;
    const auto listing = [](const std::string& host, std::uint8_t network) {
        auto c = client_to(host, {network, 1, 0});
        if (!c) return std::string();
        const auto units = c->send_raw(CommandCode{0x05, 0x02}, std::vector<std::uint8_t>{0x00});
        EXPECT_TRUE(units.has_value());
        return units ? std::string(units->data.begin(), units->data.end()) : std::string();
    };
    const std::string scu =
        "\x12"
        "CJ1W-SCU41-V1";
    EXPECT_NE(listing("127.0.72.1", 1).find(scu), std::string::npos);
    EXPECT_EQ(listing("127.0.73.1", 2).find(scu), std::string::npos);
    auto port = client_to("127.0.72.1", {1, 1, 0x88});  // unit 2, port 1
    ASSERT_NE(port, nullptr);
    const std::string compoway = "010000601";  // CompoWay/F: node 01, sub 00, SID 0, 06 01
    const auto r = port->send_raw(CommandCode{0x28, 0x03},
                                  std::vector<std::uint8_t>(compoway.begin(), compoway.end()));
    ASSERT_TRUE(r.has_value()) << r.error().message();
    EXPECT_EQ(r->code.raw(), 0x0205);
}

}  // namespace
}  // namespace fins::test
