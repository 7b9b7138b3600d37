// One HTTP connection (http_server.hpp): reads a request under the limits, answers it
// through the pure handler (api.hpp), and goes on until the client closes, a deadline
// passes or the request upgrades to a WebSocket (/ws).
#include <chrono>
#include <optional>
#include <string>
#include <utility>

#include <boost/asio/dispatch.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/error.hpp>
#include <boost/beast/http/parser.hpp>
#include <boost/beast/http/read.hpp>
#include <boost/beast/http/write.hpp>
#include <boost/beast/websocket/rfc6455.hpp>

#include "server/metrics/metrics.hpp"
#include "web/api.hpp"
#include "web/sessions.hpp"

namespace fins::web {

namespace {

using Request = http::request<http::string_body>;
using Response = http::response<http::string_body>;

std::optional<std::string_view> header(const Request& r, http::field f) {
    const auto it = r.find(f);
    if (it == r.end()) return std::nullopt;
    return std::string_view(it->value().data(), it->value().size());
}

class HttpSession : public Connection, public std::enable_shared_from_this<HttpSession> {
  public:
    HttpSession(asio::ip::tcp::socket socket, std::shared_ptr<ServerShared> shared)
        : stream_(std::move(socket)), shared_(std::move(shared)) {}

    void start() {
        asio::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->read(); });
    }

    void close() override {
        open_ = false;
        beast::error_code ignored;
        stream_.socket().shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
        stream_.close();
    }

  private:
    const WebOptions& options() const { return shared_->context.options; }

    void read() {
        if (!open_ || shared_->stopped) return;
        parser_.emplace();
        parser_->body_limit(options().max_body_bytes);
        parser_->header_limit(static_cast<std::uint32_t>(options().max_header_bytes));
        // The first request has the request deadline; later ones the idle one first.
        stream_.expires_after(requests_ == 0 ? options().request_timeout : options().idle_timeout);
        http::async_read(
            stream_, buffer_, *parser_,
            [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
    }

    void on_read(beast::error_code ec) {
        if (!open_ || shared_->stopped) return;
        if (ec == http::error::end_of_stream || ec == beast::error::timeout ||
            ec == asio::error::operation_aborted || ec == asio::error::connection_reset ||
            ec == asio::error::eof)
            return close();
        if (ec == http::error::header_limit)
            return fail(431, "the request's header is larger than " +
                                 std::to_string(options().max_header_bytes) + " bytes");
        if (ec == http::error::body_limit)
            return fail(413, "the request's body is larger than " +
                                 std::to_string(options().max_body_bytes) + " bytes");
        if (ec) return fail(400, "malformed HTTP request: " + ec.message());
        ++requests_;
        Request request = parser_->release();
        std::size_t fields = 0;
        for ([[maybe_unused]] const auto& f : request)
            ++fields;
        if (fields > options().max_header_fields)
            return fail(431, "the request has more than " +
                                 std::to_string(options().max_header_fields) + " header fields");
        const bool upgrade = beast::websocket::is_upgrade(request);
        RequestMeta meta{
            std::string_view(request.method_string().data(), request.method_string().size()),
            std::string_view(request.target().data(), request.target().size()),
            header(request, http::field::host),
            header(request, http::field::origin),
            header(request, http::field::authorization),
            upgrade};
        if (auto refused = check_request(options(), meta))
            return answer(request, std::move(*refused));
        if (upgrade) {
            if (request.target() != "/ws")
                return answer(request, error_answer(404, "WebSocket is at /ws"));
            open_ = false;  // the WebSocket session owns the stream now
            stream_.expires_never();
            return run_websocket_session(std::move(stream_), std::move(request), shared_);
        }
        const std::string_view body = request.body();
        handle_request(shared_->context, meta.method, meta.target, body,
                       [self = shared_from_this(), request](HttpAnswer a) {
                           if (!self->open_ || self->shared_->stopped) return;
                           self->answer(request, std::move(a));
                       });
    }

    // An error the request cannot recover from: answer and close.
    void fail(unsigned status, std::string message) {
        Request none;
        none.keep_alive(false);
        answer(none, error_answer(status, message));
    }

    void answer(const Request& request, HttpAnswer a) {
        server::metrics::note_http_request(a.status);
        response_.emplace(static_cast<http::status>(a.status),
                          request.version() ? request.version() : 11);
        set_common_headers(*response_);
        response_->set(http::field::content_type, a.content_type);
        response_->keep_alive(request.keep_alive());
        if (request.method() != http::verb::head) response_->body() = std::move(a.body);
        response_->prepare_payload();
        stream_.expires_after(options().request_timeout);
        http::async_write(stream_, *response_,
                          [self = shared_from_this()](beast::error_code ec, std::size_t) {
                              const bool again = !ec && self->response_->keep_alive();
                              self->response_.reset();
                              if (!again) return self->close();
                              self->read();
                          });
    }

    beast::tcp_stream stream_;
    beast::flat_buffer buffer_;  // bounded by the parser's header and body limits
    std::optional<http::request_parser<http::string_body>> parser_;
    std::optional<Response> response_;
    std::shared_ptr<ServerShared> shared_;
    std::size_t requests_ = 0;
    bool open_ = true;
};

}  // namespace

void run_http_session(asio::ip::tcp::socket socket, std::shared_ptr<ServerShared> shared) {
    auto session = std::make_shared<HttpSession>(std::move(socket), shared);
    shared->connections.push_back(session);
    session->start();
}

}  // namespace fins::web
