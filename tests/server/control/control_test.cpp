// ControlServer (server/control/control.hpp) over a real Unix-domain socket: every request
// verb, garbage, over-long lines, pipelining, connection limits and socket-file
// handling. The server runs on its own io_context thread; the test talks to it only
// through sockets (and reads the Plc after that thread has stopped). Every wait is
// bounded by poll timeouts.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "server/control/control.hpp"
#include "server/control/control_client.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

class Control : public ::testing::Test {
  protected:
    void SetUp() override {
        path_ = socket_path();
        auto s = server::ControlServer::start(io_, plc_, path_);
        ASSERT_TRUE(s) << s.error().message();
        server_ = std::move(*s);
        thread_ = std::thread([this] { io_.run(); });
    }
    void TearDown() override { stop(); }
    void stop() {
        if (!thread_.joinable()) return;
        asio::post(io_, [this] {
            server_->stop();
            io_.stop();
        });
        thread_.join();
    }
    Json status(ControlClient& c) {
        auto j = c.request(R"({"cmd":"status"})");
        EXPECT_EQ(j["ok"], true) << j.dump();
        return j["status"];
    }

    asio::io_context io_{1};
    plc::Plc plc_;
    std::filesystem::path path_;
    std::unique_ptr<server::ControlServer> server_;
    std::thread thread_;
};

TEST_F(Control, StatusSnapshotOfAnIdleCpu) {
    ControlClient c(path_);
    ASSERT_TRUE(c.connected());
    const Json s = status(c);
    EXPECT_EQ(s["mode"], "run");
    EXPECT_EQ(s["running"], true);
    EXPECT_EQ(s["end_code_flags"], "0000");
    EXPECT_EQ(s["error_code"], "0000");
    EXPECT_TRUE(s["errors"].empty());
    EXPECT_EQ(s["access_right_holder"], nullptr);
    EXPECT_EQ(s["network_write_protection"], false);
}

TEST_F(Control, BatteryFalFalsAndClear) {
    ControlClient c(path_);
    EXPECT_EQ(c.request(R"({"cmd":"battery_error","on":true})")["ok"], true);
    EXPECT_EQ(status(c)["end_code_flags"], "0040");
    EXPECT_EQ(c.request(R"({"cmd":"fal","number":5,"message":"LOW OIL"})")["ok"], true);
    EXPECT_EQ(c.request(R"({"cmd":"fals","number":7})")["ok"], true);
    Json s = status(c);
    EXPECT_EQ(s["end_code_flags"], "00C0");
    EXPECT_EQ(s["fatal_errors"], "0040");
    EXPECT_EQ(s["non_fatal_errors"], "8010");
    EXPECT_EQ(s["error_code"], "C107");
    EXPECT_EQ(s["running"], false);
    EXPECT_EQ(s["mode"], "run");
    EXPECT_EQ(s["error_log_records"], 3);
    EXPECT_EQ(c.request(R"({"cmd":"clear_errors","code":"C107"})")["ok"], true);
    EXPECT_EQ(status(c)["end_code_flags"], "0040");
    EXPECT_EQ(c.request(R"({"cmd":"clear_errors"})")["ok"], true);
    s = status(c);
    EXPECT_EQ(s["end_code_flags"], "0000");
    EXPECT_EQ(s["battery_low"], false);
}

TEST_F(Control, OtherErrorCodesByHexOrNumber) {
    ControlClient c(path_);
    EXPECT_EQ(c.request(R"({"cmd":"error","code":"0203"})")["ok"], true);
    EXPECT_EQ(c.request(R"({"cmd":"error","code":"0x80F0"})")["ok"], true);
    EXPECT_EQ(c.request(R"({"cmd":"error","code":155})")["ok"], true);  // 009B
    const Json s = status(c);
    EXPECT_EQ(s["fatal_errors"], "0200");
    EXPECT_EQ(s["non_fatal_errors"], "0480");
    EXPECT_EQ(s["error_code"], "80F0");
    for (const char* bad :
         {R"({"cmd":"error","code":"1234"})", R"({"cmd":"error","code":"4105"})",
          R"({"cmd":"error","code":"xyz"})", R"({"cmd":"error","code":-1})", R"({"cmd":"error"})"})
        EXPECT_TRUE(c.request(bad).contains("error")) << bad;
}

TEST_F(Control, MessagesModeProtectionAndAccessRight) {
    ControlClient c(path_);
    EXPECT_EQ(c.request(R"({"cmd":"message","number":3,"text":"TANK FULL"})")["ok"], true);
    EXPECT_EQ(status(c)["messages"]["3"], "TANK FULL");
    EXPECT_EQ(c.request(R"({"cmd":"message","number":3})")["ok"], true);
    EXPECT_TRUE(status(c)["messages"].empty());
    EXPECT_EQ(c.request(R"({"cmd":"network_write_protection","on":true})")["ok"], true);
    EXPECT_EQ(status(c)["network_write_protection"], true);
    EXPECT_EQ(c.request(R"({"cmd":"mode","mode":"program"})")["ok"], true);
    EXPECT_EQ(status(c)["mode"], "program");
    EXPECT_EQ(c.request(R"({"cmd":"mode","mode":"monitor"})")["ok"], true);
    EXPECT_EQ(status(c)["mode"], "monitor");
    EXPECT_EQ(c.request(R"({"cmd":"release_access_right"})")["ok"], true);
    stop();
    EXPECT_EQ(plc_.mode(), plc::OperatingMode::monitor);
    EXPECT_TRUE(plc_.network_write_protection());
}

// Like a Programming Device: protecting may set a password, releasing needs it
// (W342 5-1-3 2602 "incorrect password"); a wrong one leaves the UM protected.
TEST_F(Control, UmReadProtectionIsReleasedOnlyWithItsPassword) {
    ControlClient c(path_);
    EXPECT_EQ(c.request(R"({"cmd":"um_read_protection","on":true,"password":"SECRET"})")["ok"],
              true);
    EXPECT_EQ(status(c)["um_read_protection"], true);
    auto wrong = c.request(R"({"cmd":"um_read_protection","on":false,"password":"nope"})");
    EXPECT_EQ(wrong["error"], "incorrect password");
    EXPECT_EQ(c.request(R"({"cmd":"um_read_protection","on":false})")["error"],
              "incorrect password");
    EXPECT_EQ(status(c)["um_read_protection"], true);
    EXPECT_EQ(c.request(R"({"cmd":"um_read_protection","on":false,"password":"SECRET"})")["ok"],
              true);
    EXPECT_EQ(status(c)["um_read_protection"], false);
}

TEST_F(Control, BadRequestsAnswerAnErrorAndKeepTheConnection) {
    ControlClient c(path_);
    const std::vector<std::string> garbage = {
        "hello",
        "{}",
        "[1,2,3]",
        "null",
        R"({"cmd":5})",
        R"({"cmd":"nope"})",
        R"({"cmd":"fal","number":"5"})",
        R"({"cmd":"fal","number":0})",
        R"({"cmd":"fal","number":512})",
        R"({"cmd":"fals","number":1,"message":"SEVENTEEN CHARS!!"})",
        R"({"cmd":"fal","number":1,"message":"caf\u00e9"})",
        R"({"cmd":"battery_error","on":"yes"})",
        R"({"cmd":"message","number":8,"text":"X"})",
        R"({"cmd":"message","number":1,"text":"012345678901234567890123456789012"})",
        R"({"cmd":"mode","mode":"debug"})",
        std::string("\xff\xfe\x00\x01 binary", 12),
        "{\"cmd\":\"status\"",
        "",
    };
    for (const auto& g : garbage) {
        const Json j = c.request(g);
        ASSERT_TRUE(j.is_object()) << g;
        EXPECT_TRUE(j.contains("error")) << g << " -> " << j.dump();
    }
    EXPECT_EQ(status(c)["errors"].size(), 0u);  // still connected, nothing changed
}

TEST_F(Control, PipelinedRequestsAnswerInOrder) {
    ControlClient c(path_);
    c.send_raw("{\"cmd\":\"fal\",\"number\":1}\r\n{\"cmd\":\"bogus\"}\n{\"cmd\":\"status\"}\n");
    EXPECT_EQ(Json::parse(c.line())["ok"], true);
    EXPECT_TRUE(Json::parse(c.line()).contains("error"));
    EXPECT_EQ(Json::parse(c.line())["status"]["error_code"], "4101");
}

TEST_F(Control, OverlongLineIsRefusedAndTheConnectionClosed) {
    ControlClient c(path_);
    c.send_raw(std::string(9000, 'x'));  // more than the 8192-byte line limit
    const Json j = Json::parse(c.line(), nullptr, false);
    ASSERT_TRUE(j.is_object());
    EXPECT_TRUE(j.contains("error"));
    EXPECT_TRUE(c.closed());
    ControlClient again(path_);  // the server itself is fine
    EXPECT_EQ(status(again)["mode"], "run");
}

TEST_F(Control, StopRemovesTheSocketFile) {
    EXPECT_TRUE(std::filesystem::exists(path_));
    stop();
    EXPECT_FALSE(std::filesystem::exists(path_));
}

TEST(ControlStart, ReplacesAStaleSocketButNotALiveOneOrARegularFile) {
    asio::io_context io;
    plc::Plc plc;
    const auto path = socket_path();
    {
        auto first = server::ControlServer::start(io, plc, path);
        ASSERT_TRUE(first);
        // Still listening: another finsd owns it.
        auto busy = server::ControlServer::start(io, plc, path);
        ASSERT_FALSE(busy);
        EXPECT_EQ(busy.error(), std::make_error_code(std::errc::address_in_use));
        // A socket file nobody listens on any more is stale: replaced.
        const auto stale = socket_path();
        {
            const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
            sockaddr_un a{};
            a.sun_family = AF_UNIX;
            std::strncpy(a.sun_path, stale.c_str(), sizeof a.sun_path - 1);
            ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a), 0);
            ::close(fd);
        }
        ASSERT_TRUE(std::filesystem::is_socket(stale));
        auto second = server::ControlServer::start(io, plc, stale);
        ASSERT_TRUE(second) << second.error().message();
    }
    const auto file = socket_path();
    std::ofstream(file) << "not a socket";
    auto refused = server::ControlServer::start(io, plc, file);
    EXPECT_FALSE(refused);
    EXPECT_TRUE(std::filesystem::exists(file));
    std::filesystem::remove(file);
    EXPECT_FALSE(server::ControlServer::start(io, plc, std::string(200, 'a')));
}

}  // namespace
}  // namespace fins::test

namespace fins::test {
namespace {

// File memory: the card can be removed and inserted at run time (22 xx answer 2301
// while it is out; 05 01 reports the capacity).
TEST_F(Control, CardInsertAndRemove) {
    ControlClient c(path_);
    ASSERT_TRUE(c.connected());
    EXPECT_EQ(status(c)["memory_card_kbytes"], 30720);
    EXPECT_EQ(c.request(R"({"cmd":"card","inserted":false})")["ok"], true);
    EXPECT_EQ(status(c)["memory_card_kbytes"], 0);
    EXPECT_EQ(c.request(R"({"cmd":"card","inserted":true,"kbytes":2048})")["ok"], true);
    EXPECT_EQ(status(c)["memory_card_kbytes"], 2048);
    EXPECT_TRUE(c.request(R"({"cmd":"card","inserted":true,"kbytes":0})").contains("error"));
    EXPECT_TRUE(c.request(R"({"cmd":"card"})").contains("error"));
    EXPECT_EQ(status(c)["memory_card_kbytes"], 2048);
}

}  // namespace
}  // namespace fins::test
