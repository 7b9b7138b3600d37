// The listener of finsd's HTTP server (contract in http_server.hpp): it only accepts,
// enforces the connection limit and hands each socket to an HTTP session.
#include "web/http_server.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/write.hpp>

#include "server/metrics/metrics.hpp"
#include "web/api.hpp"
#include "web/sessions.hpp"

namespace fins::web {

namespace {

void serve(const std::shared_ptr<ServerShared>& shared, asio::ip::tcp::socket socket) {
    if (shared->open_connections() >= shared->context.options.max_connections) {
        // Full: say so and close; the connections being served keep their slots.
        auto answer = std::make_shared<std::string>();
        const std::string body =
            error_answer(503, fmt::format("finsd serves at most {} HTTP connections",
                                          shared->context.options.max_connections))
                .body;
        *answer = fmt::format(
            "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\n"
            "Content-Security-Policy: {}\r\nX-Frame-Options: DENY\r\n"
            "X-Content-Type-Options: nosniff\r\nConnection: close\r\n"
            "Content-Length: {}\r\n\r\n{}",
            content_security_policy, body.size(), body);
        server::metrics::note_http_request(503);
        auto s = std::make_shared<asio::ip::tcp::socket>(std::move(socket));
        asio::async_write(*s, asio::buffer(*answer), [s, answer](beast::error_code, std::size_t) {
            beast::error_code ignored;
            s->close(ignored);
        });
    } else {
        run_http_session(std::move(socket), shared);
    }
}

void accept(const std::shared_ptr<ServerShared>& shared) {
    shared->acceptor.async_accept([shared](beast::error_code ec, asio::ip::tcp::socket socket) {
        if (shared->stopped || ec == asio::error::operation_aborted) return;
        if (!ec)
            guarded(
                *shared, "accept", [&] { serve(shared, std::move(socket)); }, [] {});
        accept(shared);
    });
}

}  // namespace

void note_handler_failure(ServerShared& shared, std::string_view where, std::string_view what) {
    server::metrics::note_web_handler_failure();
    const auto n = shared.failures.note();
    if (n == 0) {
        spdlog::debug("web: {} failed: {}", where, what);
        return;
    }
    spdlog::error(
        "web: {} failed: {} (answered 500 or closed, the server goes on{}; "
        "fins_web_handler_failures_total counts them)",
        where, what, n > 1 ? fmt::format("; {} failures since the last such line", n) : "");
}

Result<std::unique_ptr<HttpServer>> HttpServer::start(asio::io_context& io, WebContext context) {
    beast::error_code ec;
    const auto address = asio::ip::make_address(context.options.bind_address, ec);
    if (ec) return Unexpected(std::make_error_code(std::errc::invalid_argument));
    if (!context.executor) context.executor = io.get_executor();
    auto shared = std::make_shared<ServerShared>(io, std::move(context));
    const asio::ip::tcp::endpoint endpoint(address, shared->context.options.port);
    auto& acceptor = shared->acceptor;
    const auto failed = [&] {
        return Unexpected(std::error_code(ec.value(), std::system_category()));
    };
    if (acceptor.open(endpoint.protocol(), ec); ec) return failed();
    if (acceptor.set_option(asio::socket_base::reuse_address(true), ec); ec) return failed();
    if (acceptor.bind(endpoint, ec); ec) return failed();
    if (acceptor.listen(asio::socket_base::max_listen_connections, ec); ec) return failed();
    shared->context.options.port = acceptor.local_endpoint().port();
    accept(shared);
    return std::unique_ptr<HttpServer>(new HttpServer(std::move(shared)));
}

HttpServer::HttpServer(std::shared_ptr<ServerShared> shared) : shared_(std::move(shared)) {}

HttpServer::~HttpServer() {
    stop();
}

std::uint16_t HttpServer::port() const noexcept {
    return shared_->context.options.port;
}

std::size_t HttpServer::connections() const noexcept {
    return shared_->open_connections();
}

std::size_t HttpServer::websockets() const noexcept {
    return shared_->websockets;
}

void HttpServer::stop() {
    if (!shared_ || shared_->stopped) return;
    shared_->stopped = true;
    beast::error_code ignored;
    shared_->acceptor.close(ignored);
    shared_->tick.cancel();
    for (auto& w : shared_->connections)
        if (auto c = w.lock()) c->close();
    shared_->connections.clear();
}

}  // namespace fins::web
