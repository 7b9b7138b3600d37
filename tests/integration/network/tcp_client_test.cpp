// finsd as a FINS/TCP client between two real processes on loopback (W596 1-4, 3):
// node 1 has [[remote]] transport = "tcp" for node 5, a finsd with FINS/UDP off, and
// runs `finsd ctl send|recv|sendcmd` over that connection; node 5 stops (node 1 reports
// "connection not established") and comes back on the same port (node 1 reconnects).
#include <algorithm>
#include <chrono>
#include <csignal>
#include <initializer_list>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

// finsd node 5, FINS/TCP only, on `port` (0: a free one).
std::unique_ptr<Finsd> node_b(std::uint16_t port) {
    return std::make_unique<Finsd>(std::vector<std::string>{"--node", "5", "--no-udp"},
                                   FinsdOptions{.port = port});
}

// A FINS/TCP client of node 5 (it has no FINS/UDP).
std::unique_ptr<Client> client_of_b(const Finsd& b) {
    ClientOptions o;
    o.protocol = ClientOptions::Protocol::tcp;
    o.destination = {0, 5, 0};
    o.timeout = std::chrono::milliseconds(3000);
    return b.client(o);
}

class TcpClientConnection : public ::testing::Test {
  protected:
    void start_a(std::uint16_t b_port) {
        const auto file = dir_.write("a.toml",
                                     "[memory]\nD100 = [0x1234, 0x5678]\n"
                                     "[[remote]]\nnode = 5\naddress = \"127.0.0.1:" +
                                         std::to_string(b_port) + "\"\ntransport = \"tcp\"\n");
        a_ = std::make_unique<Finsd>(
            std::vector<std::string>{"--config", file, "--control", socket_path()});
        ASSERT_TRUE(a_->started()) << a_->result().err;
    }
    std::string socket_path() const { return (dir_.path() / "ctl.sock").string(); }
    Json ctl_json(std::vector<std::string> args, int* exit_code = nullptr) {
        std::vector<std::string> argv{finsd_path, "ctl", "--socket", socket_path()};
        argv.insert(argv.end(), args.begin(), args.end());
        argv.emplace_back("--json");
        const auto r = run(argv);
        if (exit_code != nullptr) *exit_code = r.exit_code;
        return Json::parse(r.out, nullptr, false);
    }
    // A Send of D100-D101 to D200 on node 5, repeated (bounded: 300 x 50 ms) while it
    // ends with `retry_while` (6: not sent, 5: no response); its last exit code.
    int send_until(std::initializer_list<int> retry_while, Json* last = nullptr) {
        int exit_code = -1;
        for (int i = 0; i < 300; ++i) {
            const auto j = ctl_json({"send", "--dest", "0.5.0", "--local", "D100", "--remote",
                                     "D200", "--count", "2", "--timeout", "5"},
                                    &exit_code);
            if (last != nullptr) *last = j;
            if (std::find(retry_while.begin(), retry_while.end(), exit_code) == retry_while.end())
                break;
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
        return exit_code;
    }

    ScratchDir dir_{"tcpclient"};
    std::unique_ptr<Finsd> a_;
};

TEST_F(TcpClientConnection, W596_3_InstructionsGoOverItAndItComesBackAfterTheServerRestarts) {
    auto b = node_b(0);
    ASSERT_TRUE(b->started()) << b->result().err;
    ASSERT_NE(b->port(), 0);
    const auto port = b->port();
    start_a(port);

    // Until the connection is up a Send ends with 0800 0101 (exit 6).
    EXPECT_EQ(send_until({6}), 0);
    {
        auto c = client_of_b(*b);
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(words_of(*c, "D200", 2), (std::vector<std::uint16_t>{0x1234, 0x5678}));
        ASSERT_TRUE(c->write_words(addr("D210"), std::vector<std::uint16_t>{7, 8}).has_value());
    }
    int exit_code = -1;
    auto recv =
        ctl_json({"recv", "--dest", "0.5.0", "--remote", "D210", "--local", "D300", "--count", "2"},
                 &exit_code);
    EXPECT_EQ(exit_code, 0) << recv.dump();
    EXPECT_EQ(recv["result"]["words"], Json::array({7, 8}));
    auto cmd =
        ctl_json({"sendcmd", "--dest", "0.5.0", "--command", "0101 8200D200 0002"}, &exit_code);
    EXPECT_EQ(exit_code, 0) << cmd.dump();
    EXPECT_EQ(cmd["result"]["response"], "0101000000070008");

    // Node 5 stops: W596 3 "FINS/TCP connection has not been established": 0800 0101.
    b->stop();
    Json down;
    EXPECT_EQ(send_until({0, 5}, &down), 6) << down.dump();
    EXPECT_EQ(down["result"]["error_id"], "0800");
    EXPECT_EQ(down["result"]["error_id_ex"], "0101");

    // Node 5 comes back on the same port: node 1 reconnects by itself.
    b = node_b(port);
    ASSERT_EQ(b->port(), port);
    EXPECT_EQ(send_until({6}), 0);
    auto c = client_of_b(*b);
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(words_of(*c, "D200", 2), (std::vector<std::uint16_t>{0x1234, 0x5678}));
}

TEST_F(TcpClientConnection, ConfigErrorsNameTheKey) {
    const auto bad = dir_.write("bad.toml",
                                "[[remote]]\nnode = 5\naddress = \"127.0.0.1\"\n"
                                "transport = \"serial\"\n");
    auto r = run({finsd_path, "--config", bad, "--port", "0"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("remote[0].transport"), std::string::npos) << r.err;
    const auto udp_node = dir_.write("udp_node.toml",
                                     "[[remote]]\nnode = 5\naddress = \"127.0.0.1\"\n"
                                     "client_node = 3\n");
    r = run({finsd_path, "--config", udp_node, "--port", "0"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("client_node needs transport"), std::string::npos) << r.err;
    std::string many = "[network]\nmax_connections = 1\n";
    for (int node = 5; node < 7; ++node)
        many += "[[remote]]\nnode = " + std::to_string(node) +
                "\naddress = \"127.0.0.1\"\ntransport = \"tcp\"\n";
    r = run({finsd_path, "--config", dir_.write("many.toml", many), "--port", "0"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("max_connections is 1"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace fins::test
