// The state an HTTP server's sessions share, and the two session kinds (http_server.hpp).
// Internal to src/web/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>

#include "server/sessions/log_summary.hpp"
#include "web/subscriptions.hpp"
#include "web/web_context.hpp"

namespace fins::web {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;

class Connection {
  public:
    virtual ~Connection() = default;
    virtual void close() = 0;
    // The server's tick (every min_interval while some WebSocket has subscriptions):
    // sends what is due within `budget` (words, taken from it); true while this
    // connection has subscriptions.
    virtual bool poll(SteadyTime /*now*/, std::chrono::system_clock::time_point /*wall*/,
                      std::size_t& /*budget*/) {
        return false;
    }
};

struct ServerShared {
    explicit ServerShared(asio::io_context& io, WebContext c)
        : context(std::move(c)), acceptor(io), tick(io), resumable(context.options) {}
    WebContext context;
    asio::ip::tcp::acceptor acceptor;
    // One timer polls every WebSocket in the same phase, so a shared Watch is read once
    // per interval and every subscriber's delta is the same text.
    asio::steady_timer tick;
    bool ticking = false;
    ResumeStore resumable;
    std::list<std::weak_ptr<Connection>> connections;
    std::size_t websockets = 0;
    bool stopped = false;
    // The failure boundary's log line: at most one a second (the rest at debug level).
    server::LogSummary failures{std::chrono::seconds(1)};

    [[nodiscard]] std::size_t open_connections() {
        connections.remove_if([](const auto& w) { return w.expired(); });
        return connections.size();
    }
};

// Serves HTTP requests on `socket` until it closes or upgrades to a WebSocket.
void run_http_session(asio::ip::tcp::socket socket, std::shared_ptr<ServerShared> shared);
// Arms the tick if it is not armed (a WebSocket subscribed).
void arm_tick(const std::shared_ptr<ServerShared>& shared);
// Takes over `stream` after the upgrade request `request` passed the checks.
void run_websocket_session(beast::tcp_stream stream, http::request<http::string_body> request,
                           std::shared_ptr<ServerShared> shared);

// The failure boundary (docs/web.md "Security rules"): a handler threw `what` at `where`.
// Counts fins_web_handler_failures_total and logs at most one line a second; the caller
// answers 500 or closes the connection, and the server goes on.
void note_handler_failure(ServerShared& shared, std::string_view where, std::string_view what);

// Runs `f`; an exception it throws goes to note_handler_failure and `failed()` (which must
// not throw: it answers 500 or closes). Every session handler runs inside one.
template <class F, class Failed>
void guarded(ServerShared& shared, std::string_view where, F&& f, Failed&& failed) noexcept {
    try {
        f();
        return;
    } catch (const std::exception& e) {
        note_handler_failure(shared, where, e.what());
    } catch (...) {
        note_handler_failure(shared, where, "an exception that is not a std::exception");
    }
    failed();
}

inline constexpr std::string_view content_security_policy =
    "default-src 'self'; frame-ancestors 'none'";

// Content-Security-Policy and the other headers every answer carries (no page may frame
// finsd's: clickjacking of its buttons).
template <class Message>
void set_common_headers(Message& m) {
    m.set(http::field::server, "finsd");
    m.set("Content-Security-Policy", content_security_policy);
    m.set("X-Frame-Options", "DENY");
    m.set("X-Content-Type-Options", "nosniff");
    m.set(http::field::cache_control, "no-store");
}

}  // namespace fins::web
