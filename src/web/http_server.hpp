// finsd's HTTP and WebSocket server (Boost.Beast) on finsd's own io_context: the request
// handler (api.hpp) and the subscriptions (subscriptions.hpp) touch the virtual PLC on
// the one thread that runs FINS, so nothing needs a lock.
//
// After Beast's advanced_server example: a listener that only accepts (listener in
// http_server.cpp), an HTTP session (http_session.cpp) and a WebSocket session
// (websocket_session.cpp) as separate small classes. Limits (WebOptions): connections,
// header bytes and fields (431), body bytes (413), a deadline for each request and for
// idle keep-alive connections, every byte of a request (trailers, chunk framing),
// WebSocket message size and rate, subscriptions, a bounded send queue per WebSocket and
// a words budget per tick. Every answer carries Content-Security-Policy: default-src
// 'self'; frame-ancestors 'none' and X-Frame-Options: DENY. Every handler runs inside the
// failure boundary (sessions.hpp guarded()): an exception never reaches io_context::run.
#pragma once

#include <cstdint>
#include <memory>

#include <boost/asio/io_context.hpp>

#include "fins/error.hpp"
#include "web/web_context.hpp"

namespace fins::web {

struct ServerShared;

class HttpServer {
  public:
    // Binds context.options.bind_address:port (port 0: a free one) and starts accepting;
    // the caller runs `io`.
    static Result<std::unique_ptr<HttpServer>> start(boost::asio::io_context& io,
                                                     WebContext context);
    ~HttpServer();
    HttpServer(const HttpServer&) = delete;
    HttpServer& operator=(const HttpServer&) = delete;

    [[nodiscard]] std::uint16_t port() const noexcept;
    // Open HTTP and WebSocket connections.
    [[nodiscard]] std::size_t connections() const noexcept;
    [[nodiscard]] std::size_t websockets() const noexcept;
    // Closes the listener and every connection; pending handlers finish on `io`.
    void stop();

  private:
    explicit HttpServer(std::shared_ptr<ServerShared> shared);
    std::shared_ptr<ServerShared> shared_;
};

}  // namespace fins::web
