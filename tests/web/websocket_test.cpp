// finsd's WebSocket over real loopback sockets with a Beast client: hello, snapshot,
// deltas of what a write changed, seq rising by one, resume on a new connection, bad
// messages answered, and the Origin check on the upgrade. No timing is asserted: each
// wait is for a message, bounded by the stream's deadline.
#include <gtest/gtest.h>

#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/websocket.hpp>

#include "web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;
namespace websocket = beast::websocket;

class WsClient {
  public:
    explicit WsClient(std::uint16_t port, std::string origin = {}) : ws_(io_) {
        auto& s = beast::get_lowest_layer(ws_);
        s.expires_after(std::chrono::seconds(10));
        s.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
        ws_.set_option(websocket::stream_base::decorator([origin](websocket::request_type& r) {
            if (!origin.empty()) r.set(http::field::origin, origin);
        }));
        ws_.handshake("127.0.0.1", "/ws");
    }
    void send(const std::string& text) {
        beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(10));
        ws_.write(asio::buffer(text));
    }
    Json receive() {
        beast::flat_buffer b;
        beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(10));
        ws_.read(b);
        return Json::parse(beast::buffers_to_string(b.data()));
    }
    // The next message for subscription `id` (others, e.g. topics, are skipped; bounded).
    Json receive_for(const std::string& id) {
        for (int i = 0; i < 50; ++i) {
            auto m = receive();
            if (m.value("id", "") == id) return m;
        }
        ADD_FAILURE() << "no message for " << id;
        return {};
    }

  private:
    asio::io_context io_;
    websocket::stream<beast::tcp_stream> ws_;
};

TEST(WebSocket, SnapshotThenDeltasWithRisingSeq) {
    WebServer s;
    WsClient ws(s.port());
    auto hello = ws.receive();
    EXPECT_EQ(hello["type"], "hello");
    EXPECT_EQ(hello["session"].get<std::string>().size(), 32u);
    ws.send(R"({"op":"subscribe","id":"s1","address":"D0","count":10})");
    auto snapshot = ws.receive();
    EXPECT_EQ(
        snapshot,
        Json::parse(R"({"seq":1,"id":"s1","type":"snapshot","values":[0,0,0,0,0,0,0,0,0,0]})"));
    s.on_io([&] { s.plc().memory().words(Region::dm)[5] = 77; });
    auto delta = ws.receive();
    EXPECT_EQ(delta, Json::parse(R"({"seq":2,"id":"s1","type":"delta","changes":[[5,77]]})"));
    s.on_io([&] {
        s.plc().memory().words(Region::dm)[5] = 78;
        s.plc().memory().words(Region::dm)[9] = 1;
    });
    auto next = ws.receive();
    EXPECT_EQ(next["seq"], 3);
    EXPECT_EQ(next["changes"], Json::parse("[[5,78],[9,1]]"));
}

// The snapshot does not wait for the server's tick: with a tick of an hour it still comes.
TEST(WebSocket, TheSnapshotGoesOutAtOnceAfterTheSubscribe) {
    web::WebOptions options;
    options.min_interval = std::chrono::hours(1);
    WebServer s(options);
    s.on_io([&] { s.plc().memory().words(Region::dm)[2] = 9; });
    WsClient ws(s.port());
    ws.receive();  // hello
    ws.send(R"({"op":"subscribe","id":"s1","address":"D0","count":3})");
    EXPECT_EQ(ws.receive(),
              Json::parse(R"({"seq":1,"id":"s1","type":"snapshot","values":[0,0,9]})"));
    ws.send(R"({"op":"subscribe","id":"st","topic":"status"})");
    const auto status = ws.receive();
    EXPECT_EQ(status["id"], "st");
    EXPECT_EQ(status["value"]["mode"], "run");
}

TEST(WebSocket, BadMessagesAreAnsweredAndTheConnectionStays) {
    WebServer s;
    WsClient ws(s.port());
    ws.receive();
    ws.send("garbage");
    EXPECT_EQ(ws.receive()["type"], "error");
    ws.send(R"({"op":"subscribe","id":"x","address":"D99999"})");
    auto e = ws.receive();
    EXPECT_EQ(e["type"], "error");
    EXPECT_EQ(e["id"], "x");
    ws.send(R"({"op":"subscribe","id":"st","topic":"status"})");
    EXPECT_EQ(ws.receive()["value"]["mode"], "run");
}

TEST(WebSocket, ResumeOnANewConnectionReplaysWhatWasMissed) {
    WebServer s;
    std::string session;
    {
        WsClient ws(s.port());
        session = ws.receive()["session"];
        ws.send(R"({"op":"subscribe","id":"s1","address":"D0","count":4})");
        EXPECT_EQ(ws.receive()["seq"], 1);
        s.on_io([&] { s.plc().memory().words(Region::dm)[1] = 1; });
        EXPECT_EQ(ws.receive()["seq"], 2);
    }  // the page lost its connection having seen seq 2
    // The server notices the close (bounded wait for that event, not a timing check).
    for (int i = 0; i < 1000 && s.on_io([&] { return s.server().websockets(); }) != 0; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    // What changes meanwhile is sent to no one; the new connection asks for it.
    s.on_io([&] { s.plc().memory().words(Region::dm)[2] = 2; });
    WsClient again(s.port());
    again.receive();  // hello of the new connection
    again.send(R"({"op":"resume","session":")" + session + R"(","seq":2})");
    auto resumed = again.receive();
    EXPECT_EQ(resumed["type"], "resumed");
    EXPECT_EQ(resumed["session"], session);
    // The next message continues the old numbering and carries the change.
    auto next = again.receive_for("s1");
    EXPECT_EQ(next["seq"].get<int>(), resumed["seq"].get<int>() + 1);
    EXPECT_EQ(next["changes"], Json::parse("[[2,2]]"));
    // An unknown session: subscribe again.
    WsClient other(s.port());
    other.receive();
    other.send(R"({"op":"resume","session":"nope","seq":1})");
    EXPECT_EQ(other.receive()["type"], "resume_failed");
}

TEST(WebSocket, AnUpgradeFromAnotherOriginIsRefused) {
    WebServer s;
    EXPECT_THROW(WsClient(s.port(), "http://evil.example"), beast::system_error);
    WsClient ok(s.port(), "http://127.0.0.1:" + std::to_string(s.port()));
    EXPECT_EQ(ok.receive()["type"], "hello");
}

}  // namespace
}  // namespace fins::test
