// Issue 25: memory bytes 80-FF read as text. finsd --http (read-only) answered
// GET /api/read?as=ascii over such a word by exiting 3 ("invalid UTF-8 byte" from the JSON
// dump). Now each byte is the character of the same code point (Latin-1) in UTF-8: the
// HTTP API, a WebSocket subscription and the API's writes agree, and finsd keeps serving.
#include <gtest/gtest.h>

#include <string>

#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/websocket.hpp>

#include "integration/support/finsd_process.hpp"
#include "integration/support/free_port.hpp"
#include "plc/plc.hpp"
#include "web/api.hpp"
#include "web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;
namespace websocket = beast::websocket;

const std::string a_acute_bc =
    "A\xC3\xA1"
    "BC";  // words 41E1 4243

// Subscribes to D0 (2 words, as=ascii) over a WebSocket and returns the snapshot.
Json ascii_snapshot(std::uint16_t port) {
    asio::io_context io;
    websocket::stream<beast::tcp_stream> ws(io);
    auto& s = beast::get_lowest_layer(ws);
    s.expires_after(std::chrono::seconds(10));
    s.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    ws.handshake("127.0.0.1", "/ws");
    ws.write(asio::buffer(
        std::string(R"({"op":"subscribe","id":"t","address":"D0","count":2,"as":"ascii"})")));
    for (int i = 0; i < 20; ++i) {  // the hello, maybe topics, then the snapshot
        beast::flat_buffer b;
        s.expires_after(std::chrono::seconds(10));
        ws.read(b);
        auto m = Json::parse(beast::buffers_to_string(b.data()), nullptr, false);
        EXPECT_FALSE(m.is_discarded()) << beast::buffers_to_string(b.data());
        if (m.value("id", "") == "t") return m;
    }
    ADD_FAILURE() << "no snapshot";
    return {};
}

TEST(Latin1Text, FinsdAnswersAsciiReadsOfBytesAbove7F) {
    const auto port = free_tcp_port();
    Finsd finsd({"--http", "127.0.0.1:" + std::to_string(port)});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    auto fins = finsd.client();
    ASSERT_NE(fins, nullptr);
    ASSERT_TRUE(fins->write_words(addr("D0"), std::vector<std::uint16_t>{0x41E1, 0x4243}));
    {
        HttpClient http(port);
        auto r = http.request(http::verb::get, "/api/read?address=D0&count=2&as=ascii");
        EXPECT_EQ(r.result_int(), 200u) << r.body();
        const auto j = body_json(r);
        ASSERT_FALSE(j.is_discarded()) << r.body();
        EXPECT_EQ(j["values"], Json::array({a_acute_bc}));
    }
    auto snapshot = ascii_snapshot(port);
    EXPECT_EQ(snapshot["type"], "snapshot") << snapshot;
    EXPECT_EQ(snapshot["values"], Json::array({a_acute_bc})) << snapshot;
    // Still serving, over HTTP and FINS.
    HttpClient again(port);
    EXPECT_EQ(body_json(again.request(http::verb::get, "/api/read?address=D1"))["values"],
              Json::array({0x4243}));
    EXPECT_EQ(words_of(*fins, "D0", 1), std::vector<std::uint16_t>{0x41E1});
    EXPECT_EQ(finsd.stop().exit_code, 0);
}

class Latin1Api : public ::testing::Test {
  protected:
    Latin1Api() {
        server::ControlTarget t;
        t.plc = &plc_;
        t.addresses = {{0, 1}};
        context_.targets.push_back(t);
        context_.options.control = true;
    }
    web::HttpAnswer call(std::string_view method, std::string_view target,
                         std::string_view body = {}) {
        web::HttpAnswer answer;
        web::handle_request(context_, method, target, body,
                            [&](web::HttpAnswer a) { answer = std::move(a); });
        return answer;
    }
    std::uint16_t dm(std::size_t i) { return plc_.memory().words(Region::dm)[i]; }

    plc::Plc plc_;
    web::WebContext context_;
};

// Every byte 01-FF: written as text through the API, read back as the same text.
TEST_F(Latin1Api, EveryByteWritesAndReadsBackAsTheSameText) {
    std::string text;
    for (unsigned b = 1; b <= 0xFF; ++b)
        text += latin1_to_utf8(std::string(1, static_cast<char>(b)));
    auto w = call("POST", "/api/write",
                  Json{{"address", "D100"}, {"values", text}, {"as", "ascii"}}.dump());
    ASSERT_EQ(w.status, 200u) << w.body;
    EXPECT_EQ(dm(100), 0x0102);
    EXPECT_EQ(dm(227), 0xFF00);  // 255 bytes: the last word padded with 00
    auto r = call("GET", "/api/read?address=D100&count=128&as=ascii");
    ASSERT_EQ(r.status, 200u) << r.body;
    EXPECT_EQ(Json::parse(r.body)["values"], Json::array({text}));
    EXPECT_EQ(call("POST", "/api/write", R"({"address":"D0","values":"°C","as":"ascii"})").status,
              200u);
    EXPECT_EQ(dm(0), 0xB043);
}

TEST_F(Latin1Api, WritesTheTextCannotHoldAre400) {
    struct Case {
        std::string body;
        std::string error;
    };
    const Case cases[] = {
        {R"({"address":"D0","values":"A\u0100","as":"ascii"})",
         "cannot write that text as a string: character 2 is U+0100, above U+00FF: a PLC byte "
         "holds one character U+0000-U+00FF (Latin-1)"},
        {R"({"address":"D0","values":"A\u0000","as":"ascii"})",
         "cannot write that text as a string: character 2 is U+0000, which would end the "
         "string in PLC memory (00 ends a string)"},
        {R"({"address":"D0","values":[3.5e38],"as":"float"})",
         "'3.5e+38' is out of range for float (at most 3.40282e+38 either side of 0)"},
        {R"({"address":"D0","values":["3.5e38"],"as":"float"})",
         "'3.5e38' is out of range for float (at most 3.40282e+38 either side of 0)"},
        {R"({"address":"D0","values":["1e309"],"as":"double"})",
         "'1e309' is out of range for double"},
        {R"({"address":"D0","values":["--5"],"as":"int16"})", "'--5' is not a valid int16 value"},
        {R"({"address":"D0","values":["--5"]})", "'--5' is not a valid uint16 value"},
    };
    for (const auto& c : cases) {
        auto a = call("POST", "/api/write", c.body);
        EXPECT_EQ(a.status, 400u) << c.body;
        const auto j = Json::parse(a.body, nullptr, false);
        ASSERT_TRUE(j.is_object()) << a.body;
        EXPECT_EQ(j["error"], c.error) << c.body;
    }
    // A JSON number beyond double's range is no JSON the API reads.
    EXPECT_EQ(
        call("POST", "/api/write", R"({"address":"D0","values":[1e309],"as":"double"})").status,
        400u);
    EXPECT_EQ(dm(0), 0);
    EXPECT_EQ(dm(1), 0);
}

}  // namespace
}  // namespace fins::test
