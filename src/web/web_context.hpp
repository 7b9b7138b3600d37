// What finsd's HTTP/WebSocket front (src/web/) serves and under which rules. Built by
// finsd (finsd/web_setup) for a single node or a plant; read by the pure request
// handler (api.hpp), the WebSocket subscriptions (subscriptions.hpp) and the sessions.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <nlohmann/json.hpp>

#include "server/control/control.hpp"
#include "web/watches.hpp"

namespace fins::web {

struct WebOptions {
    std::string bind_address = "127.0.0.1";
    std::uint16_t port = 0;  // the port actually bound (Host and Origin checks use it)
    // POST /api/write and /api/control; off: 403 and nothing reaches the PLC.
    bool control = false;
    // Non-empty: POST requests must carry "Authorization: Bearer <token>" (required
    // when bound beyond loopback with control on).
    std::string token;
    // Host names besides the loopback ones and the bound address that the Host header
    // (and so a browser's Origin) may name: DNS rebinding protection.
    std::vector<std::string> allowed_hosts;
    // Origins besides the page's own ("http://" + the Host header) that may POST and open
    // /ws, compared whole and case-insensitively: "https://scada.lan" (a TLS proxy).
    std::vector<std::string> allowed_origins;

    std::size_t max_body_bytes = 64 * 1024;   // 413 beyond
    std::size_t max_header_bytes = 8 * 1024;  // 431 beyond (request line + fields)
    std::size_t max_header_fields = 64;       // 431 beyond
    std::size_t max_connections = 64;         // HTTP + WebSocket; the oldest idle one goes
    std::chrono::milliseconds idle_timeout{std::chrono::seconds(30)};     // HTTP keep-alive
    std::chrono::milliseconds request_timeout{std::chrono::seconds(10)};  // a begun request
    // GET /api/plcs builds its entries at most this long at a time (at least one entry),
    // then lets the io_context serve FINS before the next slice (docs/web.md).
    std::chrono::microseconds listing_slice{1000};

    // WebSocket.
    std::size_t max_ws_message_bytes = 4 * 1024;
    // Client messages and pings per connection per second (a burst of as many); beyond:
    // closed with 1008 (policy violation).
    std::size_t max_ws_messages_per_second = 100;
    // Keep-alive: a client silent for half of it is pinged; one that does not answer
    // (nothing received, not even the pong) by the end of it is closed.
    std::chrono::milliseconds websocket_idle_timeout{std::chrono::seconds(60)};
    std::size_t max_subscriptions = 64;           // per connection
    std::size_t max_queued_messages = 32;         // per connection; beyond: drop to snapshots
    std::chrono::milliseconds min_interval{100};  // per subscription: at most 10 updates/s
    // Work of one tick (every min_interval), in words read (Watch::cost()): per connection
    // and in all. Subscriptions beyond it wait for the next tick, round-robin, so FINS
    // keeps most of the I/O thread whatever the pages watch (docs/web.md).
    std::size_t max_ws_words_per_tick_per_connection = 8 * 1024;
    std::size_t max_ws_words_per_tick = 32 * 1024;
    std::size_t history_messages = 256;  // kept per connection for "resume"
    std::chrono::milliseconds resume_window{std::chrono::seconds(30)};  // a closed one kept
    std::size_t max_resumable = 16;  // closed connections kept for "resume"
};

struct WebContext {
    std::vector<server::ControlTarget> targets;  // the first is the default CPU Unit
    WebOptions options;
    // The io_context's executor (HttpServer::start sets it when empty): GET /api/plcs
    // posts its slices to it. Empty (the unit tests' plain calls): built in one go.
    boost::asio::any_io_executor executor;
    // Adds what the server around a CPU Unit knows (its network, routes, relays, FINS/TCP
    // connections, UDP peers) to its /api/plcs entry and its /api/status object. Optional.
    std::function<void(const server::ControlTarget&, nlohmann::json& plc)> describe;
    std::function<void(const server::ControlTarget&, nlohmann::json& status)> network_status;
    // The Prometheus text of GET /metrics; absent: 404.
    std::function<std::string()> metrics;
    // What every connection's subscriptions watch, each read once per interval.
    std::shared_ptr<Watches> watches = std::make_shared<Watches>();
    // Tests only (absent in finsd): called at the failure boundary's points, "http request"
    // (before a request's route), "websocket message" (before a client message is handled)
    // and "websocket poll" (a connection's share of the tick), so a test can make each throw.
    std::function<void(std::string_view point)> fault;
};

}  // namespace fins::web
