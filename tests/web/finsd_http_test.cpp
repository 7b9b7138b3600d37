// finsd --http as users run it: a finsd process, FINS clients and an HTTP client side by
// side. A value written over FINS is read over HTTP, one written over HTTP is read over
// FINS, the mode set over HTTP is what 06 01 answers, and the start-up refusals.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>

#include "integration/support/finsd_process.hpp"
#include "integration/support/free_port.hpp"
#include "web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

TEST(FinsdHttp, FinsAndHttpSeeTheSamePlc) {
    ScratchDir dir("http");
    const auto port = free_tcp_port();
    Finsd finsd({"--http", "127.0.0.1:" + std::to_string(port), "--http-control", "--control",
                 (dir.path() / "ctl.sock").string()});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    auto fins = finsd.client();
    ASSERT_NE(fins, nullptr);
    ASSERT_TRUE(fins->write_words(addr("D100"), std::vector<std::uint16_t>{1234}));
    HttpClient http(port);
    EXPECT_EQ(body_json(http.request(http::verb::get, "/api/read?address=D100"))["values"],
              Json::array({1234}));
    auto w = http.request(http::verb::post, "/api/write",
                          R"({"address":"D200","values":[-2],"as":"int16"})");
    EXPECT_EQ(w.result_int(), 200u) << w.body();
    EXPECT_EQ(words_of(*fins, "D200", 1), std::vector<std::uint16_t>{0xFFFE});
    auto mode =
        http.request(http::verb::post, "/api/control", R"({"cmd":"mode","mode":"program"})");
    EXPECT_EQ(mode.result_int(), 200u) << mode.body();
    auto status = fins->send_raw(CommandCode{0x06, 0x01}, {});
    ASSERT_TRUE(status);
    ASSERT_GE(status->data.size(), 2u);
    EXPECT_EQ(status->data[1], 0x00);  // 06 01 mode: PROGRAM
    auto plcs = body_json(http.request(http::verb::get, "/api/plcs"));
    EXPECT_EQ(plcs["plcs"][0]["udp_port"], finsd.port());
    EXPECT_EQ(finsd.stop().exit_code, 0);
}

// /api/status lists who talks FINS to this node: the FINS/UDP peers with the node their
// frames named and when, and the FINS/TCP connections with the node of their handshake.
TEST(FinsdHttp, StatusNamesTheUdpPeersAndTcpNodes) {
    const auto port = free_tcp_port();
    Finsd finsd({"--http", "127.0.0.1:" + std::to_string(port)});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    ClientOptions udp;
    udp.port = finsd.port();
    udp.source.node = 77;
    udp.timeout = std::chrono::milliseconds(3000);
    auto u = Client::connect(udp);
    ASSERT_TRUE(u) << u.error().message();
    ASSERT_TRUE((*u)->read_words(addr("D0"), 1));
    ClientOptions tcp = udp;
    tcp.protocol = ClientOptions::Protocol::tcp;
    tcp.source.node = 33;
    auto t = Client::connect(tcp);
    ASSERT_TRUE(t) << t.error().message();
    ASSERT_TRUE((*t)->read_words(addr("D0"), 1));  // the handshake is done
    HttpClient http(port);
    const auto status = body_json(http.request(http::verb::get, "/api/status"));
    ASSERT_EQ(status["udp_peers"].size(), 1u) << status["udp_peers"];
    EXPECT_EQ(status["udp_peers"][0]["address"], "127.0.0.1");
    EXPECT_EQ(status["udp_peers"][0]["node"], 77);
    EXPECT_EQ(status["udp_peers"][0]["last_seen"].get<std::string>().size(), 20u);  // ...Z
    ASSERT_EQ(status["connections"].size(), 1u) << status["connections"];
    EXPECT_EQ(status["connections"][0]["address"], "127.0.0.1");
    EXPECT_EQ(status["connections"][0]["node"], 33);
    EXPECT_EQ(status["connections"][0]["state"], "established");
    EXPECT_TRUE(status["relays"].is_object());  // one node, no router: nothing relayed
    EXPECT_EQ(finsd.stop().exit_code, 0);
}

// The page's Scenario panel reads /api/status: a CPU Unit running a scenario carries what
// `finsd ctl scenario status` answers (time, ticks, events), one without carries nothing.
TEST(FinsdHttp, StatusCarriesTheRunningScenario) {
    ScratchDir dir("http-scenario");
    const auto port = free_tcp_port();
    const std::string conveyor = std::string(FINS_SOURCE_DIR) + "/examples/scenarios/conveyor.toml";
    Finsd finsd({"--http", "127.0.0.1:" + std::to_string(port), "--http-control", "--scenario",
                 conveyor, "--control", (dir.path() / "ctl.sock").string()});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    HttpClient http(port);
    auto advance = http.request(http::verb::post, "/api/control",
                                R"({"cmd":"scenario","action":"advance","seconds":2.5})");
    EXPECT_EQ(advance.result_int(), 200u) << advance.body();
    const auto status = body_json(http.request(http::verb::get, "/api/status"));
    ASSERT_TRUE(status.contains("scenario")) << status;
    EXPECT_EQ(status["scenario"]["time"], "virtual");
    EXPECT_DOUBLE_EQ(status["scenario"]["time_s"].get<double>(), 2.5);
    EXPECT_EQ(status["scenario"]["ticks"], 25);
    EXPECT_EQ(status["scenario"]["seed"], 7);
    ASSERT_TRUE(status["scenario"]["events"].is_array());
    EXPECT_EQ(status["scenario"]["events"][0]["name"], "jam");
    EXPECT_EQ(finsd.stop().exit_code, 0);

    const auto plain_port = free_tcp_port();
    Finsd plain({"--http", "127.0.0.1:" + std::to_string(plain_port)});
    ASSERT_TRUE(plain.started()) << plain.result().err;
    HttpClient plain_http(plain_port);
    EXPECT_FALSE(
        body_json(plain_http.request(http::verb::get, "/api/status")).contains("scenario"));
    EXPECT_EQ(plain.stop().exit_code, 0);
}

TEST(FinsdHttp, ReadOnlyByDefault) {
    const auto port = free_tcp_port();
    Finsd finsd({"--http", "127.0.0.1:" + std::to_string(port)});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    HttpClient http(port);
    EXPECT_EQ(http.request(http::verb::post, "/api/write", R"({"address":"D100","values":[1]})")
                  .result_int(),
              403u);
    auto fins = finsd.client();
    EXPECT_EQ(words_of(*fins, "D100", 1), std::vector<std::uint16_t>{0});
}

TEST(FinsdHttp, ControlBeyondLoopbackWithoutATokenDoesNotStart) {
    Finsd finsd({"--http", "0.0.0.0:0", "--http-control"});
    ASSERT_FALSE(finsd.started());
    EXPECT_EQ(finsd.result().exit_code, 2);
    EXPECT_NE(finsd.result().err.find("--http-token-file"), std::string::npos)
        << finsd.result().err;
}

}  // namespace
}  // namespace fins::test
