// finsd's WebSocket over real loopback sockets with a Beast client: hello, snapshot,
// deltas of what a write changed, seq rising by one, resume on a new connection, bad
// messages answered, and the Origin check on the upgrade. No timing is asserted: each
// wait is for a message, bounded by the stream's deadline.
#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <stdexcept>
#include <string>

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
        ws_.handshake("127.0.0.1:" + std::to_string(port), "/ws");
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

    // Sends `n` pings as fast as the socket takes them (stops when the server closed).
    void ping_flood(int n) {
        beast::error_code ec;
        for (int i = 0; i < n && !ec; ++i) {
            beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(10));
            ws_.ping({}, ec);
        }
    }
    void send_flood(const std::string& text, int n) {
        beast::error_code ec;
        for (int i = 0; i < n && !ec; ++i) {
            beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(10));
            ws_.write(asio::buffer(text), ec);
        }
    }
    // Reads (skipping messages, bounded) until the server closes: its close code, or -1
    // when the connection ended without a close frame.
    int close_code() {
        for (int i = 0; i < 10000; ++i) {
            beast::flat_buffer b;
            beast::error_code ec;
            beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(10));
            ws_.read(b, ec);
            if (ec == websocket::error::closed) return ws_.reason().code;
            if (ec) return -1;
        }
        return -2;
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
    // Not any IP literal or port: only the page's own origin (the Host it was reached at).
    EXPECT_THROW(WsClient(s.port(), "http://127.0.0.2:9000"), beast::system_error);
    EXPECT_THROW(WsClient(s.port(), "http://127.0.0.1:1"), beast::system_error);
    EXPECT_THROW(WsClient(s.port(), "null"), beast::system_error);
    WsClient ok(s.port(), "http://127.0.0.1:" + std::to_string(s.port()));
    EXPECT_EQ(ok.receive()["type"], "hello");
}

TEST(WebSocket, SessionIdsAre128RandomBitsInHex) {
    WebServer s;
    std::set<std::string> seen;
    for (int i = 0; i < 8; ++i) {
        WsClient ws(s.port());
        const auto id = ws.receive()["session"].get<std::string>();
        EXPECT_EQ(id.size(), 32u);
        EXPECT_EQ(id.find_first_not_of("0123456789abcdef"), std::string::npos) << id;
        seen.insert(id);
    }
    EXPECT_EQ(seen.size(), 8u);
}

std::uint64_t failures() {
    return server::metrics::process_metrics().web_handler_failures.load();
}

TEST(WebSocketFailureBoundary, AThrowingMessageHandlerClosesThatConnectionOnly) {
    std::atomic<int> throws{1};
    WebServer s({}, 1, [&](std::string_view point) {
        if (point == "websocket message" && throws.fetch_sub(1) > 0)
            throw std::runtime_error("injected");
    });
    const auto before = failures();
    WsClient other(s.port());
    EXPECT_EQ(other.receive()["type"], "hello");
    WsClient ws(s.port());
    EXPECT_EQ(ws.receive()["type"], "hello");
    ws.send(R"({"op":"subscribe","id":"s1","address":"D0","count":1})");
    EXPECT_EQ(ws.close_code(), -1);  // closed, no close frame
    EXPECT_EQ(failures(), before + 1);
    // The other connection and new ones are served.
    other.send(R"({"op":"subscribe","id":"s1","address":"D0","count":1})");
    EXPECT_EQ(other.receive_for("s1")["type"], "snapshot");
    WsClient again(s.port());
    EXPECT_EQ(again.receive()["type"], "hello");
}

TEST(WebSocketFailureBoundary, AThrowingPollClosesThatConnectionAndTheTickGoesOn) {
    std::atomic<int> throws{0};
    WebServer s({}, 1, [&](std::string_view point) {
        if (point == "websocket poll" && throws.fetch_sub(1) > 0)
            throw std::runtime_error("injected");
    });
    const auto before = failures();
    WsClient ws(s.port());
    EXPECT_EQ(ws.receive()["type"], "hello");
    ws.send(R"({"op":"subscribe","id":"s1","address":"D0","count":1})");
    EXPECT_EQ(ws.receive_for("s1")["type"], "snapshot");
    throws = 1;
    s.on_io([&] { s.plc().memory().words(Region::dm)[0] = 1; });
    EXPECT_EQ(ws.close_code(), -1);
    EXPECT_EQ(failures(), before + 1);
    WsClient next(s.port());
    EXPECT_EQ(next.receive()["type"], "hello");
    next.send(R"({"op":"subscribe","id":"s1","address":"D0","count":1})");
    EXPECT_EQ(next.receive_for("s1")["values"], Json::array({1}));
    s.on_io([&] { s.plc().memory().words(Region::dm)[0] = 2; });
    EXPECT_EQ(next.receive_for("s1")["type"], "delta");  // the tick still runs
}

TEST(WebSocketBudget, APingFloodIsClosedWithPolicyViolation) {
    web::WebOptions o;
    o.max_ws_messages_per_second = 20;
    WebServer s(o);
    const auto before = server::metrics::process_metrics().websocket_policy_closes.load();
    WsClient ws(s.port());
    EXPECT_EQ(ws.receive()["type"], "hello");
    ws.ping_flood(1000);
    EXPECT_EQ(ws.close_code(), static_cast<int>(websocket::close_code::policy_error));
    EXPECT_EQ(server::metrics::process_metrics().websocket_policy_closes.load(), before + 1);
    WsClient next(s.port());
    EXPECT_EQ(next.receive()["type"], "hello");
}

TEST(WebSocketBudget, AMessageFloodIsClosedWithPolicyViolation) {
    web::WebOptions o;
    o.max_ws_messages_per_second = 20;
    WebServer s(o);
    WsClient ws(s.port());
    EXPECT_EQ(ws.receive()["type"], "hello");
    ws.send_flood(R"({"op":"unsubscribe","id":"none"})", 1000);
    EXPECT_EQ(ws.close_code(), static_cast<int>(websocket::close_code::policy_error));
}

TEST(WebSocketBudget, ABurstWithinTheBudgetIsServed) {
    web::WebOptions o;
    o.max_ws_messages_per_second = 20;
    WebServer s(o);
    WsClient ws(s.port());
    EXPECT_EQ(ws.receive()["type"], "hello");
    for (int i = 0; i < 10; ++i)
        ws.send(R"({"op":"subscribe","id":"s)" + std::to_string(i) +
                R"(","address":"D0","count":1})");
    for (int i = 0; i < 10; ++i)
        EXPECT_EQ(ws.receive_for("s" + std::to_string(i))["type"], "snapshot");
}

}  // namespace
}  // namespace fins::test
