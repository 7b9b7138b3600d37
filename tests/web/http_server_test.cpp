// finsd's HTTP server over real loopback sockets with a Beast client: the routes, the
// limits (431, 413, 503), malformed HTTP, the security rules, and that a refused write
// never reaches the PLC.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

TEST(HttpServer, ServesThePageAndTheApiWithTheSecurityHeaders) {
    WebServer s;
    HttpClient c(s.port());
    auto page = c.request(http::verb::get, "/");
    EXPECT_EQ(page.result_int(), 200u);
    EXPECT_EQ(page[http::field::content_type], "text/html; charset=utf-8");
    EXPECT_EQ(page["Content-Security-Policy"], "default-src 'self'; frame-ancestors 'none'");
    // Keep-alive: the same connection serves the next requests.
    s.on_io([&] { s.plc().memory().words(Region::dm)[100] = 42; });
    auto read = c.request(http::verb::get, "/api/read?address=D100&count=2");
    EXPECT_EQ(read.result_int(), 200u);
    EXPECT_EQ(body_json(read), Json::parse(R"({"address":"D100","as":"uint16","values":[42,0]})"));
    EXPECT_EQ(read["Content-Security-Policy"], "default-src 'self'; frame-ancestors 'none'");
    auto status = c.request(http::verb::get, "/api/status");
    EXPECT_EQ(body_json(status)["mode"], "run");
    EXPECT_EQ(c.request(http::verb::get, "/api/plcs").result_int(), 200u);
    EXPECT_EQ(c.request(http::verb::get, "/openapi.yaml").result_int(), 200u);
    EXPECT_EQ(c.request(http::verb::get, "/chart.js").result_int(), 200u);
    auto missing = c.request(http::verb::get, "/nope");
    EXPECT_EQ(missing.result_int(), 404u);
    EXPECT_TRUE(body_json(missing).contains("error"));
    EXPECT_EQ(c.request(http::verb::put, "/api/write").result_int(), 405u);
}

TEST(HttpServer, WritesWithControlOffAre403AndNothingReachesThePlc) {
    WebServer s;
    HttpClient c(s.port());
    auto r = c.request(http::verb::post, "/api/write", R"({"address":"D100","values":[7]})");
    EXPECT_EQ(r.result_int(), 403u);
    EXPECT_TRUE(body_json(r).contains("error"));
    auto mode = c.request(http::verb::post, "/api/control", R"({"cmd":"mode","mode":"program"})");
    EXPECT_EQ(mode.result_int(), 403u);
    EXPECT_EQ(s.word(Region::dm, 100), 0);
    EXPECT_EQ(s.on_io([&] { return s.plc().mode(); }), plc::OperatingMode::run);
}

TEST(HttpServer, WritesAndControlsWithControlOn) {
    web::WebOptions o;
    o.control = true;
    WebServer s(o);
    HttpClient c(s.port());
    auto r = c.request(http::verb::post, "/api/write", R"({"address":"D100","values":[7,8]})");
    EXPECT_EQ(r.result_int(), 200u) << r.body();
    EXPECT_EQ(s.word(Region::dm, 101), 8);
    auto mode = c.request(http::verb::post, "/api/control", R"({"cmd":"mode","mode":"program"})");
    EXPECT_EQ(mode.result_int(), 200u) << mode.body();
    EXPECT_EQ(s.on_io([&] { return s.plc().mode(); }), plc::OperatingMode::program);
    // Another origin may not change the PLC (a page elsewhere posting to loopback).
    auto cross = c.request(http::verb::post, "/api/write", R"({"address":"D100","values":[9]})",
                           {{"Origin", "http://evil.example"}});
    EXPECT_EQ(cross.result_int(), 403u);
    EXPECT_EQ(s.word(Region::dm, 100), 7);
}

TEST(HttpServer, ABearerTokenGuardsPosts) {
    web::WebOptions o;
    o.control = true;
    o.token = "t0ken";
    WebServer s(o);
    HttpClient c(s.port());
    EXPECT_EQ(
        c.request(http::verb::post, "/api/write", R"({"address":"D1","values":[1]})").result_int(),
        403u);
    EXPECT_EQ(c.request(http::verb::post, "/api/write", R"({"address":"D1","values":[1]})",
                        {{"Authorization", "Bearer t0ken"}})
                  .result_int(),
              200u);
    EXPECT_EQ(s.word(Region::dm, 1), 1);
}

TEST(HttpServer, MalformedHttpGets400AndTheConnectionCloses) {
    WebServer s;
    HttpClient c(s.port());
    auto r = c.raw("THIS IS NOT HTTP\r\n\r\n");
    EXPECT_EQ(r.result_int(), 400u);
    EXPECT_TRUE(body_json(r).contains("error"));
    EXPECT_TRUE(c.closed());
}

TEST(HttpServer, OversizedBodiesAndHeadersAreRefused) {
    web::WebOptions o;
    o.control = true;
    WebServer s(o);
    {
        HttpClient c(s.port());
        auto r =
            c.raw("POST /api/write HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 100000\r\n\r\n");
        EXPECT_EQ(r.result_int(), 413u);
        EXPECT_TRUE(body_json(r).contains("error"));
    }
    {
        HttpClient c(s.port());
        auto r = c.raw("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Big: " + std::string(9000, 'a') +
                       "\r\n\r\n");
        EXPECT_EQ(r.result_int(), 431u);
    }
    {
        HttpClient c(s.port());
        std::string many = "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n";
        for (int i = 0; i < 70; ++i)
            many += "X-" + std::to_string(i) + ": 1\r\n";
        auto r = c.raw(many + "\r\n");
        EXPECT_EQ(r.result_int(), 431u);
    }
    {
        HttpClient c(s.port());
        auto r = c.request(http::verb::get, "/", {}, {{"Host", "rebound.example"}});
        EXPECT_EQ(r.result_int(), 403u);
    }
    EXPECT_EQ(s.word(Region::dm, 0), 0);
}

TEST(HttpServer, BeyondTheConnectionLimitAnswers503) {
    web::WebOptions o;
    o.max_connections = 2;
    WebServer s(o);
    HttpClient a(s.port());
    HttpClient b(s.port());
    EXPECT_EQ(a.request(http::verb::get, "/api/plcs").result_int(), 200u);
    EXPECT_EQ(b.request(http::verb::get, "/api/plcs").result_int(), 200u);
    HttpClient third(s.port());
    auto r = third.read();
    EXPECT_EQ(r.result_int(), 503u);
    EXPECT_TRUE(body_json(r).contains("error"));
}

TEST(HttpServer, AnIdleConnectionIsClosedAtItsDeadline) {
    web::WebOptions o;
    o.request_timeout = std::chrono::milliseconds(200);
    o.idle_timeout = std::chrono::milliseconds(200);
    WebServer s(o);
    HttpClient c(s.port());
    EXPECT_TRUE(c.closed());  // sent nothing: closed, not held forever
}

TEST(HttpServer, APlantServesEveryCpuUnit) {
    WebServer s({}, 2);
    s.on_io([&] { s.plc(1).memory().words(Region::dm)[0] = 5; });
    HttpClient c(s.port());
    auto plcs = body_json(c.request(http::verb::get, "/api/plcs"));
    ASSERT_EQ(plcs["plcs"].size(), 2u);
    EXPECT_EQ(plcs["plcs"][1]["name"], "plc2");
    EXPECT_EQ(body_json(c.request(http::verb::get, "/api/read?address=D0&plc=plc2"))["values"][0],
              5);
    EXPECT_EQ(body_json(c.request(http::verb::get, "/api/read?address=D0&plc=1.1"))["values"][0],
              5);
}

}  // namespace
}  // namespace fins::test
