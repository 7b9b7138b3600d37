// The loopback control channel (ControlTransport::loopback_tcp, control_channel_file.hpp;
// finsd's channel on Windows, issue 28) on Linux: the channel file's format and mode, the
// token line before the same JSON lines, connections without it closed unanswered, the
// same limits as the Unix socket, and stale / live / foreign files at the path. The
// server runs on its own io_context thread; every wait is bounded (ControlClient's).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "server/control/control.hpp"
#include "server/control/control_channel_file.hpp"
#include "server/control/control_client.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;
using server::ControlTransport;

const std::string token = "0123456789abcdef0123456789abcdef";

std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), {}};
}

server::ControlOptions loopback_options() {
    server::ControlOptions options;
    options.transport = ControlTransport::loopback_tcp;
    options.token = token;
    return options;
}

Result<std::unique_ptr<server::ControlServer>> start(asio::io_context& io, plc::Plc& plc,
                                                     const std::filesystem::path& path,
                                                     server::ControlOptions options) {
    server::ControlTarget target;
    target.plc = &plc;
    return server::ControlServer::start(io, {target}, path, std::move(options));
}

class ControlLoopback : public ::testing::Test {
  protected:
    void start_server(server::ControlOptions options = loopback_options()) {
        path_ = socket_path();
        auto s = start(io_, plc_, path_, std::move(options));
        ASSERT_TRUE(s) << s.error().message();
        server_ = std::move(*s);
        const auto channel = server::read_channel_file(path_);
        ASSERT_TRUE(channel);
        port_ = channel->port;
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

    asio::io_context io_{1};
    plc::Plc plc_;
    std::filesystem::path path_;
    std::uint16_t port_ = 0;
    std::unique_ptr<server::ControlServer> server_;
    std::thread thread_;
};

TEST_F(ControlLoopback, ChannelFileNamesThePortAndTokenForItsOwnerOnlyAndGoesAtStop) {
    start_server();
    const std::string text = read_file(path_);
    EXPECT_EQ(text, std::to_string(port_) + " " + token + "\n");
    struct stat st {};
    ASSERT_EQ(::stat(path_.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 07777, 0600U);
    stop();
    EXPECT_FALSE(std::filesystem::exists(path_));
}

TEST_F(ControlLoopback, TheTokenLineThenTheSameJsonAsTheUnixSocket) {
    start_server();
    ControlClient c(port_);
    ASSERT_TRUE(c.connected());
    c.send_raw(token + "\r\n");
    Json j = c.request(R"({"cmd":"status"})");
    EXPECT_EQ(j["ok"], true) << j.dump();
    EXPECT_EQ(j["status"]["mode"], "run");
    EXPECT_EQ(c.request(R"({"cmd":"mode","mode":"program"})")["ok"], true);
    EXPECT_TRUE(c.request("garbage").contains("error"));  // and the connection stays
    EXPECT_EQ(c.request(R"({"cmd":"status"})")["status"]["mode"], "program");
    // Token and request in one write, as finsd ctl sends them.
    ControlClient d(port_);
    d.send_raw(token + "\n" + R"({"cmd":"status"})" + "\n");
    EXPECT_EQ(Json::parse(d.line(), nullptr, false)["status"]["mode"], "program");
}

TEST_F(ControlLoopback, WithoutTheTokenAConnectionIsClosedUnanswered) {
    start_server();
    const std::vector<std::string> first_lines = {
        R"({"cmd":"status"})",    token + "0", token.substr(1), "", std::string(9000, 'a'),
        token.substr(0, 31) + "F"};
    for (const auto& first : first_lines) {
        ControlClient c(port_);
        ASSERT_TRUE(c.connected());
        c.send_raw(first + "\n" + R"({"cmd":"mode","mode":"program"})" + "\n");
        EXPECT_EQ(c.line(), "") << first.substr(0, 40);
        EXPECT_TRUE(c.closed()) << first.substr(0, 40);
    }
    ControlClient c(port_);
    c.send_raw(token + "\n");
    EXPECT_EQ(c.request(R"({"cmd":"status"})")["status"]["mode"], "run");  // nothing changed
}

TEST_F(ControlLoopback, AClientSilentBeforeItsTokenIsClosedAtTheIdleTimeout) {
    auto options = loopback_options();
    options.idle_timeout = std::chrono::milliseconds(100);
    start_server(options);
    ControlClient c(port_);
    ASSERT_TRUE(c.connected());
    EXPECT_TRUE(c.closed());
}

TEST_F(ControlLoopback, ConnectionsWithoutTheTokenArePushedOutFirst) {
    auto options = loopback_options();
    options.max_connections = 2;
    start_server(options);
    ControlClient authenticated(port_);
    authenticated.send_raw(token + "\n");
    ASSERT_EQ(authenticated.request(R"({"cmd":"status"})")["ok"], true);
    // The idlest is `authenticated`, but the one without a token goes, again and again.
    std::vector<std::unique_ptr<ControlClient>> strangers;
    for (int i = 0; i < 4; ++i)
        strangers.push_back(std::make_unique<ControlClient>(port_));
    for (int i = 0; i < 3; ++i)
        EXPECT_TRUE(strangers[static_cast<std::size_t>(i)]->closed()) << i;
    EXPECT_EQ(authenticated.request(R"({"cmd":"status"})")["ok"], true);
}

TEST(ControlLoopbackStart, ReplacesAStaleFileButNotALiveOneOrAForeignOne) {
    asio::io_context io;
    plc::Plc plc;
    const auto path = socket_path();
    auto first = start(io, plc, path, loopback_options());
    ASSERT_TRUE(first) << first.error().message();
    const auto busy = start(io, plc, path, loopback_options());
    ASSERT_FALSE(busy);
    EXPECT_EQ(busy.error(), std::make_error_code(std::errc::address_in_use));
    (*first)->stop();
    EXPECT_FALSE(std::filesystem::exists(path));

    // A finsd killed: its file names a port nobody listens on (one just closed).
    std::uint16_t closed_port = 0;
    {
        asio::ip::tcp::acceptor a(io, {asio::ip::address_v4::loopback(), 0});
        closed_port = a.local_endpoint().port();
    }
    for (const auto& stale :
         std::vector<std::string>{std::to_string(closed_port) + " " + token + "\n", ""}) {
        std::ofstream(path) << stale;
        auto second = start(io, plc, path, loopback_options());
        ASSERT_TRUE(second) << second.error().message() << " for '" << stale << "'";
        EXPECT_NE(read_file(path), stale);
        (*second)->stop();
    }

    for (const std::string foreign : {"my notes\n", "1 short\n"}) {
        std::ofstream(path) << foreign;
        const auto refused = start(io, plc, path, loopback_options());
        ASSERT_FALSE(refused);
        EXPECT_EQ(refused.error(), std::make_error_code(std::errc::file_exists));
        EXPECT_EQ(read_file(path), foreign);
    }
    std::filesystem::remove(path);
    std::filesystem::create_directory(path);
    EXPECT_FALSE(start(io, plc, path, loopback_options()));
    std::filesystem::remove(path);

    auto no_token = loopback_options();
    no_token.token = "short";
    const auto refused = start(io, plc, path, no_token);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error(), std::make_error_code(std::errc::invalid_argument));
    EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(ControlChannelFile, ParsesPortAndTokenOnly) {
    const auto ok = server::parse_channel_file("40123 " + token + "\r\n");
    ASSERT_TRUE(ok);
    EXPECT_EQ(ok->port, 40123);
    EXPECT_EQ(ok->token, token);
    EXPECT_TRUE(server::parse_channel_file("1 " + token));
    EXPECT_TRUE(server::parse_channel_file("65535 " + token + "\n"));
    for (const auto& bad : std::vector<std::string>{
             std::string{}, "0 " + token, "65536 " + token, "-1 " + token, "x " + token,
             " " + token, "40123", "40123 ", "40123 short", "40123 " + token + " extra",
             "40123  " + token, "40123 " + token + "\n\n", "40123 " + token.substr(0, 30) + "-_",
             "40123 " + std::string(257, 'a')})
        EXPECT_FALSE(server::parse_channel_file(bad)) << bad;
}

}  // namespace
}  // namespace fins::test
