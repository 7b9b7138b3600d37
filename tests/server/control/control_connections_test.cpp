// The control channel's connections (issue 18 item 4) and its CPU Unit selector "plc"
// (a plant): idle clients never lock `finsd ctl` out, idle clients time out, clients
// that wait for an instruction never crowd out a `status`, and "plc" reaches every CPU
// Unit by name or FINS address. The server runs on its own io_context thread; every
// wait is bounded (control_client.hpp).
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "server/control/control.hpp"
#include "server/control/control_client.hpp"
#include "server/instructions/network_instructions.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

// Frames go nowhere: every instruction waits for its timeout.
class SilentTransport : public server::InstructionTransport {
  public:
    Sent send_frame(const NodeAddress&, Bytes, server::InstructionRoute&) override {
        return Sent::ok;
    }
};

class ControlConnections : public ::testing::Test {
  protected:
    void start(server::ControlOptions options) {
        path_ = socket_path();
        server::ControlTarget first;
        first.plc = &plc_;
        first.name = "press";
        first.addresses = {{1, 10}};
        first.instructions = &engine_;
        server::ControlTarget second;
        second.plc = &other_;
        second.name = "oven";
        second.addresses = {{1, 20}, {2, 20}};
        auto s = server::ControlServer::start(io_, {first, second}, path_, options);
        ASSERT_TRUE(s) << s.error().message();
        server_ = std::move(*s);
        thread_ = std::thread([this] { io_.run(); });
    }
    void TearDown() override {
        if (!thread_.joinable()) return;
        asio::post(io_, [this] {
            engine_.stop();
            server_->stop();
            io_.stop();
        });
        thread_.join();
    }
    bool status_ok(ControlClient& c) {
        const Json j = c.request(R"({"cmd":"status"})");
        return j.is_object() && j.value("ok", false);
    }

    asio::io_context io_{1};
    plc::Plc plc_;
    plc::Plc other_;
    SilentTransport transport_;
    server::NetworkInstructions engine_{io_.get_executor(), plc_, NodeAddress{1, 10, 0},
                                        transport_};
    std::filesystem::path path_;
    std::unique_ptr<server::ControlServer> server_;
    std::thread thread_;
};

// Issue 18 item 4: 16 idle connections held every slot and refused `finsd ctl` until
// one closed. A new client is served at once; the one idle the longest is closed.
TEST_F(ControlConnections, NewClientIsServedAtOnceTheLongestIdleIsClosed) {
    start({});
    std::vector<std::unique_ptr<ControlClient>> idle;
    for (int i = 0; i < 16; ++i) {
        idle.push_back(std::make_unique<ControlClient>(path_));
        ASSERT_TRUE(status_ok(*idle.back())) << i;
    }
    ControlClient newcomer(path_);
    EXPECT_TRUE(status_ok(newcomer));
    EXPECT_TRUE(idle.front()->closed());  // the first to fall silent
    for (std::size_t i = 1; i < idle.size(); ++i)
        EXPECT_TRUE(status_ok(*idle[i])) << i;  // the others keep their connection
}

// An idle control connection is closed after idle_timeout (bounded wait, no timing
// asserted: only that the close comes).
TEST_F(ControlConnections, IdleConnectionTimesOut) {
    start({.max_connections = 16, .idle_timeout = std::chrono::milliseconds(50)});
    ControlClient c(path_);
    ASSERT_TRUE(status_ok(c));
    EXPECT_TRUE(c.closed());
}

// Clients waiting for their instruction's answer hold no slot: with more of them than
// slots (20 > 16, the old hard limit that refused the 17th), a `status` is still
// answered at once.
TEST_F(ControlConnections, ClientsWaitingForInstructionsNeverStarveAStatus) {
    start({});
    constexpr int waiting_count = 20;
    std::vector<std::unique_ptr<ControlClient>> waiting;
    for (int i = 0; i < waiting_count; ++i) {
        waiting.push_back(std::make_unique<ControlClient>(path_));
        waiting.back()->send_raw(
            R"({"cmd":"sendcmd","dest":"1.30.0","command":"0501","timeout":600})"
            "\n");
    }
    // Every one of them is in flight (bounded: the requests are read within a few turns).
    ControlClient watcher(path_);
    std::size_t in_flight = 0;
    for (int round = 0; round < 200 && in_flight < waiting_count; ++round)
        in_flight = watcher.request(R"({"cmd":"instructions"})")["instructions"]["in_flight"]
                        .get<std::size_t>();
    ASSERT_EQ(in_flight, static_cast<std::size_t>(waiting_count));
    ControlClient c(path_);
    EXPECT_TRUE(status_ok(c));
    EXPECT_EQ(watcher.request(R"({"cmd":"instructions"})")["instructions"]["in_flight"],
              waiting_count);
}

// Plant item: "plc" picks the CPU Unit by [[plc]] name or by any of its FINS addresses;
// without it, the first. An unknown one is an error that names the known ones.
TEST_F(ControlConnections, PlcSelectsACpuUnitByNameOrAddress) {
    start({});
    ControlClient c(path_);
    EXPECT_EQ(c.request(R"({"cmd":"mode","mode":"program","plc":"oven"})")["ok"], true);
    EXPECT_EQ(c.request(R"({"cmd":"fal","number":3,"plc":"2.20"})")["ok"], true);
    const Json oven = c.request(R"({"cmd":"status","plc":"1.20"})");
    EXPECT_EQ(oven["status"]["plc"], "oven");
    EXPECT_EQ(oven["status"]["mode"], "program");
    EXPECT_EQ(oven["status"]["error_code"], "4103");
    const Json press = c.request(R"({"cmd":"status"})");
    EXPECT_EQ(press["status"]["plc"], "press");
    EXPECT_EQ(press["status"]["mode"], "run");
    EXPECT_EQ(press["status"]["error_code"], "0000");
    const Json unknown = c.request(R"({"cmd":"status","plc":"mixer"})");
    EXPECT_EQ(unknown["error"], "no CPU Unit \"mixer\" here (CPU Units: press, oven)");
    EXPECT_TRUE(c.request(R"({"cmd":"status","plc":"1.99"})").contains("error"));
    EXPECT_TRUE(c.request(R"({"cmd":"status","plc":7})").contains("error"));
}

}  // namespace
}  // namespace fins::test
