// WebSocket keep-alive (docs/web.md "WebSocket keep-alive"): finsd pings a client that
// has sent nothing for half of websocket_idle_timeout and closes one from which nothing
// (not even the pong) came by its end. A Beast client, which answers pings while it
// reads, stays through several ping periods; a raw TCP client that did the upgrade and
// then reads and answers nothing is closed, and its connection is gone from the
// server's counts (HttpServer::websockets() in process, fins_web_connections in a finsd
// process's /metrics). The idle timeout is 1 s so each test takes a few seconds; every
// wait is a bounded loop for an event, with a generous bound, not a timing assertion.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/websocket.hpp>

#include "integration/support/finsd_process.hpp"
#include "integration/support/free_port.hpp"
#include "web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;
namespace websocket = beast::websocket;
using namespace std::chrono_literals;

constexpr auto idle_timeout = 1s;  // a ping after 0.5 s of silence
constexpr auto generous = 20s;     // the bound of every wait for an event

// A Beast client whose reads answer the server's pings (Beast sends the pong while a
// read is pending), counting them.
class AnsweringClient {
  public:
    explicit AnsweringClient(std::uint16_t port) : ws_(io_) {
        auto& s = beast::get_lowest_layer(ws_);
        s.expires_after(10s);
        s.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
        ws_.handshake("127.0.0.1", "/ws");
        s.expires_never();  // the stream's own keep-alive settings rule from here
        ws_.control_callback([this](websocket::frame_type kind, beast::string_view) {
            if (kind == websocket::frame_type::ping) ++pings_;
        });
    }
    // Reads one message, answering the pings that come before it; nullopt when the
    // connection ended or nothing came within `bound`.
    std::optional<Json> receive(std::chrono::steady_clock::duration bound = generous) {
        start_read();
        const auto end = std::chrono::steady_clock::now() + bound;
        while (!read_done_ && std::chrono::steady_clock::now() < end)
            run_a_while();
        if (!read_done_ || read_error_) return std::nullopt;
        reading_ = false;
        auto m = Json::parse(beast::buffers_to_string(buffer_.data()), nullptr, false);
        buffer_.consume(buffer_.size());
        return m;
    }
    // Keeps a read pending (answering pings) until `pings` more came; false when the
    // connection ended first or they did not come within the bound.
    bool wait_for_pings(int pings) {
        start_read();
        const int target = pings_ + pings;
        const auto end = std::chrono::steady_clock::now() + generous;
        while (pings_ < target && !read_done_ && std::chrono::steady_clock::now() < end)
            run_a_while();
        return pings_ >= target && !read_done_;
    }
    void send(const std::string& text) {
        bool done = false;
        ws_.async_write(asio::buffer(text), [&](beast::error_code, std::size_t) { done = true; });
        const auto end = std::chrono::steady_clock::now() + generous;
        while (!done && std::chrono::steady_clock::now() < end)
            run_a_while();
    }
    [[nodiscard]] int pings() const { return pings_; }

  private:
    // A run that found no work left stops the context: restart it for the next one.
    void run_a_while() {
        io_.restart();
        io_.run_for(50ms);
    }
    void start_read() {
        if (reading_) return;
        reading_ = true;
        read_done_ = false;
        ws_.async_read(buffer_, [this](beast::error_code ec, std::size_t) {
            read_done_ = true;
            read_error_ = static_cast<bool>(ec);
        });
    }

    asio::io_context io_;
    websocket::stream<beast::tcp_stream> ws_;
    beast::flat_buffer buffer_;
    int pings_ = 0;
    bool reading_ = false;
    bool read_done_ = false;
    bool read_error_ = false;
};

// A plain TCP socket that sends the upgrade request, reads the 101 answer, and then
// neither reads nor sends anything (a browser tab frozen, a peer gone without a FIN).
class SilentClient {
  public:
    explicit SilentClient(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_port = htons(port);
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        timeval tv{10, 0};
        ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
        if (::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) return;
        const std::string upgrade =
            "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n"
            "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
            "Sec-WebSocket-Version: 13\r\n\r\n";
        if (::send(fd_, upgrade.data(), upgrade.size(), MSG_NOSIGNAL) !=
            static_cast<ssize_t>(upgrade.size()))
            return;
        // The answer's head, byte by byte so that no frame after it is taken (bounded).
        for (int i = 0; i < 4096 && head_.find("\r\n\r\n") == std::string::npos; ++i) {
            char c = 0;
            if (::recv(fd_, &c, 1, 0) != 1) break;
            head_ += c;
        }
    }
    ~SilentClient() { ::close(fd_); }
    SilentClient(const SilentClient&) = delete;
    SilentClient& operator=(const SilentClient&) = delete;

    [[nodiscard]] const std::string& head() const { return head_; }
    // After the server closed: every byte it sent, up to the end of the stream; `closed`
    // tells whether the stream ended (EOF or reset) rather than the read timing out.
    std::string drain(bool& closed) {
        std::string bytes;
        closed = false;
        char buffer[4096];
        for (int i = 0; i < 1000; ++i) {
            const auto n = ::recv(fd_, buffer, sizeof buffer, 0);
            if (n > 0) {
                bytes.append(buffer, static_cast<std::size_t>(n));
                continue;
            }
            closed = n == 0 || errno == ECONNRESET;
            break;
        }
        return bytes;
    }

  private:
    int fd_;
    std::string head_;
};

// The opcodes of the unmasked server frames in `bytes` (RFC 6455 5.2), in order.
std::vector<int> opcodes(const std::string& bytes) {
    std::vector<int> out;
    std::size_t i = 0;
    while (i + 2 <= bytes.size()) {
        const auto b0 = static_cast<unsigned char>(bytes[i]);
        const auto b1 = static_cast<unsigned char>(bytes[i + 1]);
        std::size_t length = b1 & 0x7F;
        std::size_t at = i + 2;
        if (length == 126) {
            if (at + 2 > bytes.size()) break;
            length = std::size_t{static_cast<unsigned char>(bytes[at])} << 8 |
                     std::size_t{static_cast<unsigned char>(bytes[at + 1])};
            at += 2;
        } else if (length == 127) {
            break;  // finsd sends no message of 64 KiB
        }
        out.push_back(b0 & 0x0F);
        i = at + length;
    }
    return out;
}

web::WebOptions keep_alive_options() {
    web::WebOptions o;
    o.websocket_idle_timeout = idle_timeout;
    return o;
}

// Waits (bounded) until `count()` is `want`; the last value seen.
template <class F>
std::size_t eventually(F count, std::size_t want) {
    std::size_t seen = count();
    const auto end = std::chrono::steady_clock::now() + generous;
    while (seen != want && std::chrono::steady_clock::now() < end) {
        std::this_thread::sleep_for(20ms);
        seen = count();
    }
    return seen;
}

TEST(WebSocketKeepAlive, AClientThatAnswersPingsStaysThroughSeveralPeriods) {
    WebServer s(keep_alive_options());
    AnsweringClient ws(s.port());
    const auto hello = ws.receive();
    ASSERT_TRUE(hello);
    EXPECT_EQ((*hello)["type"], "hello");
    // Four pings: two idle timeouts in which the client sent nothing of its own.
    ASSERT_TRUE(ws.wait_for_pings(4)) << "pings seen: " << ws.pings();
    EXPECT_EQ(s.on_io([&] { return s.server().websockets(); }), 1u);
    // The connection still serves: a subscription is answered with its snapshot.
    ws.send(R"({"op":"subscribe","id":"s1","address":"D0","count":1})");
    const auto snapshot = ws.receive();
    ASSERT_TRUE(snapshot);
    EXPECT_EQ((*snapshot)["type"], "snapshot");
    EXPECT_EQ((*snapshot)["values"], Json::array({0}));
}

TEST(WebSocketKeepAlive, AClientThatAnswersNothingIsPingedThenClosedAndForgotten) {
    WebServer s(keep_alive_options());
    SilentClient silent(s.port());
    ASSERT_NE(silent.head().find("101 Switching Protocols"), std::string::npos) << silent.head();
    // Another client, answering, is kept while the silent one goes.
    AnsweringClient alive(s.port());
    ASSERT_TRUE(alive.receive());
    const auto websockets = [&] { return s.on_io([&] { return s.server().websockets(); }); };
    EXPECT_EQ(websockets(), 2u);
    // The silent one is closed; the answering one keeps answering meanwhile.
    std::size_t seen = websockets();
    const auto end = std::chrono::steady_clock::now() + generous;
    while (seen != 1 && std::chrono::steady_clock::now() < end) {
        ASSERT_TRUE(alive.wait_for_pings(1));
        seen = websockets();
    }
    EXPECT_EQ(seen, 1u);
    EXPECT_EQ(eventually([&] { return s.on_io([&] { return s.server().connections(); }); }, 1), 1u);
    // What it was sent: the hello, then a ping it never answered, then the end of the
    // stream (the socket closed, no close frame waited for).
    bool closed = false;
    const auto frames = opcodes(silent.drain(closed));
    EXPECT_TRUE(closed);
    ASSERT_GE(frames.size(), 2u);
    EXPECT_EQ(frames[0], 0x1);  // text: hello
    EXPECT_EQ(frames[1], 0x9);  // ping
    ASSERT_TRUE(alive.wait_for_pings(1));
}

// --- finsd as users run it: [http] websocket_idle_timeout in the configuration file ---

// The value of `fins_web_connections{kind="websocket"}` in GET /metrics; -1 if absent.
int websocket_gauge(std::uint16_t port) {
    HttpClient http(port);
    const auto text = http.request(http::verb::get, "/metrics").body();
    const std::string key = "fins_web_connections{kind=\"websocket\"} ";
    const auto at = text.find(key);
    return at == std::string::npos ? -1 : std::stoi(text.substr(at + key.size()));
}

TEST(WebSocketKeepAlive, FinsdClosesTheSilentClientAndItsMetricGoesBack) {
    ScratchDir dir("ws-keepalive");
    const auto port = free_tcp_port();
    const auto config =
        dir.write("finsd.toml", "[http]\nlisten = \"127.0.0.1:" + std::to_string(port) +
                                    "\"\nwebsocket_idle_timeout = 1\n");
    Finsd finsd({"--config", config});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    EXPECT_EQ(websocket_gauge(port), 0);
    AnsweringClient alive(port);
    ASSERT_TRUE(alive.receive());
    SilentClient silent(port);
    ASSERT_NE(silent.head().find("101 Switching Protocols"), std::string::npos) << silent.head();
    EXPECT_EQ(websocket_gauge(port), 2);
    int seen = 2;
    const auto end = std::chrono::steady_clock::now() + generous;
    while (seen != 1 && std::chrono::steady_clock::now() < end) {
        ASSERT_TRUE(alive.wait_for_pings(1));
        seen = websocket_gauge(port);
    }
    EXPECT_EQ(seen, 1);
    bool closed = false;
    silent.drain(closed);
    EXPECT_TRUE(closed);
    EXPECT_EQ(finsd.stop().exit_code, 0);
}

TEST(WebSocketKeepAlive, FinsdRefusesAnIdleTimeoutOutOfRange) {
    ScratchDir dir("ws-keepalive-bad");
    for (const std::string value : {"0", "0.1", "3601", "\"60s\""}) {
        const auto config =
            dir.write("finsd.toml",
                      "[http]\nlisten = \"127.0.0.1:0\"\nwebsocket_idle_timeout = " + value + "\n");
        Finsd finsd({"--config", config});
        ASSERT_FALSE(finsd.started()) << value;
        EXPECT_EQ(finsd.result().exit_code, 2) << value;
        EXPECT_NE(finsd.result().err.find("http.websocket_idle_timeout: must be a number of "
                                          "seconds 0.2-3600"),
                  std::string::npos)
            << finsd.result().err;
    }
}

}  // namespace
}  // namespace fins::test
