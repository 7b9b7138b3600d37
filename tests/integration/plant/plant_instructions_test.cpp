// Each [[plc]] runs network instructions of its own ([[plc.schedule]], [[plc.remote]];
// README "A plant of several networks"), as [[schedule]] and [[remote]] do for a single
// node (W596 3): from its own units, with its own remote-node addresses.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fins/address.hpp"
#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

// line-a (1.1) and line-b (1.2) on one network, on loopback addresses no other test
// binds; both get D100 values; `a_extra` and `b_extra` are more tables of each.
std::string plant(const std::string& a_extra, const std::string& b_extra) {
    return R"(
[[plc]]
name = "line-a"
memory = { "D100" = [7, 8] }
)" + a_extra +
           R"(
  [[plc.ethernet]]
  network = 1
  bind = "127.0.71.1"
  port = 9611
[[plc]]
name = "line-b"
memory = { "D100" = [5, 6] }
)" + b_extra +
           R"(
  [[plc.ethernet]]
  network = 1
  bind = "127.0.71.2"
  port = 9611
)";
}

// Two words from line-a (node 1) or line-b (node 2).
std::vector<std::uint16_t> words_at(std::uint8_t node, const std::string& address) {
    ClientOptions o;
    o.host = "127.0.71." + std::to_string(node);
    o.destination = {1, node, 0};
    o.port = 9611;
    o.timeout = std::chrono::milliseconds(3000);
    auto c = Client::connect(o);
    EXPECT_TRUE(c) << c.error().message();
    if (!c) return {};
    auto got = (*c)->read_words(*parse_address(address), 2);
    EXPECT_TRUE(got) << got.error().message();
    return got.value_or(std::vector<std::uint16_t>{});
}

TEST(PlantInstructions, W596_3_EachCpuUnitRunsItsOwnSchedule) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-schedule");
    // line-a sends its D100-D101 to line-b's D200 (automatic generation: node 2 is
    // 127.0.71.2 at line-a's own port); line-b has no schedule.
    const auto schedule = R"(
  [[plc.schedule]]
  every = "50ms"
  instruction = "send"
  dest = "1.2.0"
  local = "D100"
  remote = "D200"
  count = 2
)";
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--config", dir.write("plant.toml", plant(schedule, "")), "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    std::vector<std::uint16_t> got;
    for (int i = 0; i < 100 && got != std::vector<std::uint16_t>{7, 8}; ++i) {
        got = words_at(2, "D200");
        if (got != std::vector<std::uint16_t>{7, 8})
            std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the next period
    }
    EXPECT_EQ(got, (std::vector<std::uint16_t>{7, 8}));
    EXPECT_EQ(words_at(1, "D200"), (std::vector<std::uint16_t>{0, 0}));
    // Issue 27: `finsd ctl --plc NAME instructions` lists that CPU Unit's schedule, as a
    // single node's lists its [[schedule]] (it used to list none in a plant).
    const auto a =
        nlohmann::json::parse(ctl(socket, {"--plc", "line-a", "instructions"}).out, nullptr, false);
    ASSERT_EQ(a["schedule"].size(), 1u) << a.dump();
    EXPECT_GE(a["schedule"][0]["done"].get<int>(), 1) << a.dump();
    const auto b =
        nlohmann::json::parse(ctl(socket, {"--plc", "line-b", "instructions"}).out, nullptr, false);
    EXPECT_EQ(b["schedule"].size(), 0u) << b.dump();
}

// A router's [[plc.schedule]] entries leave through the units their destinations are
// reached by (one schedule per unit): `finsd ctl --plc NAME instructions` lists every
// entry, in the configuration's order, whichever unit runs it (it listed none once the
// entries were spread over two units).
TEST(PlantInstructions, W596_3_ScheduleSpreadOverTwoUnitsListsEveryEntry) {
    const FixedPorts fixed_ports;
    ScratchDir dir("plant-schedule-units");
    const auto config = dir.write("plant.toml", R"(
[[plc]]
name = "router"
memory = { "D100" = [7, 8] }
  [[plc.schedule]]
  every = "50ms"
  instruction = "send"
  dest = "2.3.0"
  local = "D100"
  remote = "D300"
  count = 2
  [[plc.schedule]]
  every = "50ms"
  instruction = "send"
  dest = "1.2.0"
  local = "D100"
  remote = "D200"
  count = 2
  [[plc.ethernet]]
  unit = 0
  network = 1
  bind = "127.0.71.1"
  port = 9611
  [[plc.ethernet]]
  unit = 1
  network = 2
  bind = "127.0.72.1"
  port = 9611
[[plc]]
name = "on-1"
  [[plc.ethernet]]
  network = 1
  bind = "127.0.71.2"
  port = 9611
[[plc]]
name = "on-2"
  [[plc.ethernet]]
  network = 2
  bind = "127.0.72.3"
  port = 9611
)");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--config", config, "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    nlohmann::json listed;
    const auto both_done = [&] {
        listed = nlohmann::json::parse(ctl(socket, {"--plc", "router", "instructions"}).out,
                                       nullptr, false);
        const auto& e = listed["schedule"];
        return e.is_array() && e.size() == 2 && e[0]["done"].get<int>() >= 1 &&
               e[1]["done"].get<int>() >= 1;
    };
    for (int i = 0; i < 100 && !both_done(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the next period
    ASSERT_EQ(listed["schedule"].size(), 2u) << listed.dump();
    EXPECT_GE(listed["schedule"][0]["done"].get<int>(), 1) << listed.dump();
    EXPECT_GE(listed["schedule"][1]["done"].get<int>(), 1) << listed.dump();
    EXPECT_EQ(listed["schedule"][0]["errors"], 0) << listed.dump();
    EXPECT_EQ(listed["schedule"][1]["errors"], 0) << listed.dump();
}

// Issue 27, W596 1-4: a unit's FINS/TCP connections count its [[plc.remote]] clients, as
// a single node's count its [[remote]]s: more than max_connections is a start error.
TEST(PlantInstructions, W596_1_4_TcpRemotesCountAgainstTheUnitsConnections) {
    ScratchDir dir("plant-remote-limit");
    // `remotes` FINS/TCP [[plc.remote]]s (nothing listens: they only retry) on a unit
    // allowing `limit` connections.
    const auto config = [&](int remotes, int limit) {
        std::string text = "[[plc]]\nname = \"line-a\"\n";
        for (int node = 1; node <= remotes; ++node)
            text += "  [[plc.remote]]\n  network = 1\n  node = " + std::to_string(node + 100) +
                    "\n  address = \"127.0.0.1:9\"\n  transport = \"tcp\"\n";
        text +=
            "  [[plc.ethernet]]\n  network = 1\n  bind = \"127.0.0.1\"\n"
            "  max_connections = " +
            std::to_string(limit) + "\n";
        return dir.write("plant-" + std::to_string(limit) + ".toml", text);
    };
    Finsd refused({"--config", config(2, 1)});
    ASSERT_FALSE(refused.started());
    EXPECT_EQ(refused.result().exit_code, 2) << refused.result().err;
    EXPECT_NE(refused.result().err.find("plc[0]: 2 [[remote]] entries with transport = "
                                        "\"tcp\", but max_connections is 1"),
              std::string::npos)
        << refused.result().err;
    // Within the unit's own limit, above the default 16: served.
    Finsd served({"--config", config(17, 20)});
    ASSERT_TRUE(served.started()) << served.result().err;
    EXPECT_EQ(served.stop().exit_code, 0);
}

// A datagram socket standing for a remote node.
class RemoteNode {
  public:
    RemoteNode() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
        sockaddr_in a{};
        a.sin_family = AF_INET;
        ::inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
        EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
        socklen_t size = sizeof a;
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &size);
        port_ = ntohs(a.sin_port);
    }
    ~RemoteNode() { ::close(fd_); }
    RemoteNode(const RemoteNode&) = delete;
    RemoteNode& operator=(const RemoteNode&) = delete;
    [[nodiscard]] std::uint16_t port() const { return port_; }
    // A datagram within `ms`, or an empty one.
    std::vector<std::uint8_t> receive(int ms) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, ms) != 1) return {};
        std::vector<std::uint8_t> buf(2048);
        const auto n = ::recv(fd_, buf.data(), buf.size(), 0);
        buf.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
        return buf;
    }

  private:
    int fd_;
    std::uint16_t port_ = 0;
};

TEST(PlantInstructions, W596_2_3_RemoteNodeAddressesArePerCpuUnit) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-remote");
    RemoteNode node9;
    // Both CPU Units send 05 01 to node 1.9; only line-a knows where node 9 is (the test's
    // socket); line-b's automatic generation gives 127.0.71.9, where nothing listens.
    const auto sendcmd = R"(
  [[plc.schedule]]
  every = "50ms"
  instruction = "sendcmd"
  dest = "1.9.0"
  command = "0501"
  no_response = true
)";
    const auto remote = "  [[plc.remote]]\n  network = 1\n  node = 9\n  address = \"127.0.0.1:" +
                        std::to_string(node9.port()) + "\"\n";
    Finsd d({"--config", dir.write("plant.toml", plant(sendcmd + remote, sendcmd))});
    ASSERT_TRUE(d.started()) << d.result().err;
    for (int i = 0; i < 3; ++i) {
        const auto frame = node9.receive(5000);
        ASSERT_GE(frame.size(), 12u) << "datagram " << i;
        EXPECT_EQ(frame[3], 1);  // DNA
        EXPECT_EQ(frame[4], 9);  // DA1
        EXPECT_EQ(frame[6], 1);  // SNA
        EXPECT_EQ(frame[7], 1);  // SA1: line-a, never line-b (2)
        EXPECT_EQ(frame[10], 0x05);
        EXPECT_EQ(frame[11], 0x01);
    }
}

}  // namespace
}  // namespace fins::test
