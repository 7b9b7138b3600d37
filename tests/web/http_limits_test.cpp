// Issue 25: every byte a client sends counts against a limit (chunked trailers, chunk
// extensions, chunk-size digits, the whole request), the failure boundary (an exception
// in a handler answers 500 or closes, counts fins_web_handler_failures_total, and the
// server goes on), the Origin and Content-Type rules, and the framing headers. Real
// loopback sockets; each wait bounded by the client stream's deadline.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>

#include "web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

const std::string chunked_post =
    "POST /api/write HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
    "Transfer-Encoding: chunked\r\n\r\n";

// The status of the answer in `text` ("HTTP/1.1 431 ..."), 0 if none came.
unsigned status_of(const std::string& text) {
    if (text.rfind("HTTP/1.1 ", 0) != 0 || text.size() < 12) return 0;
    return static_cast<unsigned>(std::stoul(text.substr(9, 3)));
}

// The JSON body of the answer in `text`.
Json body_of(const std::string& text) {
    const auto end = text.find("\r\n\r\n");
    if (end == std::string::npos) return {};
    return Json::parse(text.substr(end + 4), nullptr, false);
}

// The server still answers a new connection.
void expect_serving(WebServer& s) {
    HttpClient c(s.port());
    EXPECT_EQ(c.request(http::verb::get, "/api/plcs").result_int(), 200u);
}

std::uint64_t failures() {
    return server::metrics::process_metrics().web_handler_failures.load();
}

TEST(HttpLimits, ATrailerFieldOf65534BytesIs431NotTheEndOfFinsd) {
    // Before: basic_fields threw "field value too large" out of io_context::run (finsd
    // exit 3), read-only or not.
    WebServer s;
    HttpClient c(s.port());
    const auto answer = c.raw_until_closed(
        chunked_post + "2\r\n{}\r\n0\r\nX-T: " + std::string(65534, 'a') + "\r\n\r\n");
    EXPECT_EQ(status_of(answer), 431u) << answer.substr(0, 200);
    EXPECT_TRUE(body_of(answer).contains("error"));
    expect_serving(s);
}

TEST(HttpLimits, AStreamOfTrailerFieldsIsCutAtTheBufferBound) {
    // Before: the read buffer grew without bound looking for the trailer's end.
    WebServer s;
    HttpClient c(s.port());
    std::string trailer;
    for (int i = 0; trailer.size() < 512 * 1024; ++i)
        trailer += "X-" + std::to_string(i) + ": " + std::string(100, 'b') + "\r\n";
    const auto answer = c.raw_until_closed(chunked_post + "2\r\n{}\r\n0\r\n" + trailer);
    EXPECT_EQ(status_of(answer), 431u) << answer.substr(0, 200);
    expect_serving(s);
}

TEST(HttpLimits, ALongChunkExtensionIs400) {
    WebServer s;
    HttpClient c(s.port());
    const auto answer =
        c.raw_until_closed(chunked_post + "2;" + std::string(300, 'x') + "\r\n{}\r\n0\r\n\r\n");
    EXPECT_EQ(status_of(answer), 400u) << answer.substr(0, 200);
    EXPECT_NE(body_of(answer).value("error", "").find("chunk extension"), std::string::npos);
    expect_serving(s);
}

TEST(HttpLimits, EndlessChunkSizeDigitsAreRefused) {
    WebServer s;
    HttpClient c(s.port());
    const auto answer =
        c.raw_until_closed(chunked_post + std::string(64 * 1024, '0') + "2\r\n{}\r\n0\r\n\r\n");
    const auto status = status_of(answer);
    EXPECT_TRUE(status == 400u || status == 431u) << answer.substr(0, 200);
    expect_serving(s);
}

TEST(HttpLimits, ChunkFramingCountsAgainstTheRequestBudget) {
    // Small chunks with extensions under their own bound: the body stays tiny, but the
    // bytes of the request (2 x header limit + body limit) are used up: 413.
    WebServer s;
    HttpClient c(s.port());
    std::string chunks;
    while (chunks.size() < 100 * 1024)
        chunks += "1;" + std::string(200, 'e') + "\r\n \r\n";
    const auto answer = c.raw_until_closed(chunked_post + chunks + "0\r\n\r\n");
    EXPECT_EQ(status_of(answer), 413u) << answer.substr(0, 200);
    expect_serving(s);
}

TEST(HttpLimits, AChunkedPostWithASmallTrailerIsServed) {
    web::WebOptions o;
    o.control = true;
    WebServer s(o);
    HttpClient c(s.port());
    const std::string body = R"({"address":"D5","values":[77]})";
    char size[16];
    std::snprintf(size, sizeof size, "%zx", body.size());
    auto r = c.raw(chunked_post + size + ";name=v\r\n" + body + "\r\n0\r\nX-Checksum: 1\r\n\r\n");
    EXPECT_EQ(r.result_int(), 200u) << r.body();
    EXPECT_EQ(s.word(Region::dm, 5), 77);
}

TEST(HttpLimits, PipelinedRequestsAreAnsweredInOrder) {
    WebServer s;
    HttpClient c(s.port());
    const std::string get = "GET /api/plcs HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
    auto first = c.raw(get + get + "GET /nope HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
    EXPECT_EQ(first.result_int(), 200u);
    EXPECT_EQ(c.read().result_int(), 200u);
    EXPECT_EQ(c.read().result_int(), 404u);
}

TEST(HttpFailureBoundary, AThrowingRequestHandlerAnswers500AndTheServerGoesOn) {
    std::atomic<int> throws{1};
    WebServer s({}, 1, [&](std::string_view point) {
        if (point == "http request" && throws.fetch_sub(1) > 0)
            throw std::runtime_error("injected");
    });
    const auto before = failures();
    {
        HttpClient c(s.port());
        auto r = c.request(http::verb::get, "/api/plcs");
        EXPECT_EQ(r.result_int(), 500u);
        EXPECT_TRUE(body_json(r).contains("error"));
        EXPECT_FALSE(r.keep_alive());
        EXPECT_TRUE(c.closed());
    }
    EXPECT_EQ(failures(), before + 1);
    expect_serving(s);
    HttpClient m(s.port());
    const auto metrics = m.request(http::verb::get, "/metrics").body();
    EXPECT_NE(metrics.find("fins_web_handler_failures_total "), std::string::npos);
}

TEST(HttpSecurity, EveryAnswerForbidsFraming) {
    web::WebOptions o;
    o.max_connections = 1;
    WebServer s(o);
    HttpClient c(s.port());
    for (const char* target : {"/", "/api/plcs", "/nope"}) {
        auto r = c.request(http::verb::get, target);
        EXPECT_EQ(r["Content-Security-Policy"], "default-src 'self'; frame-ancestors 'none'")
            << target;
        EXPECT_EQ(r["X-Frame-Options"], "DENY") << target;
    }
    HttpClient full(s.port());
    auto busy = full.read();
    EXPECT_EQ(busy.result_int(), 503u);
    EXPECT_EQ(busy["Content-Security-Policy"], "default-src 'self'; frame-ancestors 'none'");
    EXPECT_EQ(busy["X-Frame-Options"], "DENY");
}

TEST(HttpSecurity, OnlyThePagesOwnOriginMayPost) {
    web::WebOptions o;
    o.control = true;
    o.allowed_origins = {"https://scada.lan"};
    WebServer s(o);
    const std::string port = std::to_string(s.port());
    const std::string write = R"({"address":"D9","values":[1]})";
    const auto post = [&](std::vector<std::pair<std::string, std::string>> headers) {
        HttpClient c(s.port());
        headers.emplace_back("Host", "127.0.0.1:" + port);
        return c.request(http::verb::post, "/api/write", write, headers).result_int();
    };
    // Another IP literal, another local port, "null": a page elsewhere (Chromium wrote
    // D500 and switched to PROGRAM from http://127.0.0.2:9000 before).
    EXPECT_EQ(post({{"Origin", "http://127.0.0.2:9000"}}), 403u);
    EXPECT_EQ(post({{"Origin", "http://127.0.0.1:9000"}}), 403u);
    EXPECT_EQ(post({{"Origin", "http://localhost:" + port}}), 403u);
    EXPECT_EQ(post({{"Origin", "null"}}), 403u);
    EXPECT_EQ(s.word(Region::dm, 9), 0);
    EXPECT_EQ(post({{"Origin", "http://127.0.0.1:" + port}}), 200u);
    EXPECT_EQ(post({{"Origin", "https://scada.lan"}}), 200u);
    EXPECT_EQ(post({}), 200u);  // no Origin: curl, scripts
    EXPECT_EQ(s.word(Region::dm, 9), 1);
}

TEST(HttpSecurity, APostMustBeJson) {
    web::WebOptions o;
    o.control = true;
    WebServer s(o);
    const std::string write = R"({"address":"D3","values":[4]})";
    const auto post_as = [&](std::string type) {
        HttpClient c(s.port());
        std::string text = "POST /api/write HTTP/1.1\r\nHost: 127.0.0.1\r\n";
        if (!type.empty()) text += "Content-Type: " + type + "\r\n";
        text += "Content-Length: " + std::to_string(write.size()) + "\r\n\r\n" + write;
        auto r = c.raw(text);
        if (r.result_int() == 415u) {
            EXPECT_TRUE(body_json(r).contains("error"));
        }
        return r.result_int();
    };
    EXPECT_EQ(post_as(""), 415u);
    EXPECT_EQ(post_as("text/plain"), 415u);
    EXPECT_EQ(post_as("application/x-www-form-urlencoded"), 415u);
    EXPECT_EQ(post_as("application/jsonp"), 415u);
    EXPECT_EQ(s.word(Region::dm, 3), 0);
    EXPECT_EQ(post_as("application/json"), 200u);
    EXPECT_EQ(post_as("Application/JSON; charset=utf-8"), 200u);
    EXPECT_EQ(s.word(Region::dm, 3), 4);
}

}  // namespace
}  // namespace fins::test
