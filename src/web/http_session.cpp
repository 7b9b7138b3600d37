// One HTTP connection (http_server.hpp): reads a request under the limits, answers it
// through the pure handler (api.hpp), and goes on until the client closes, a deadline
// passes or the request upgrades to a WebSocket (/ws).
//
// Every byte a client sends counts against a limit (issue 25): the read buffer holds at
// most max_header_bytes + read_slack unparsed bytes (a header, a chunk header with its
// extensions or a trailer that does not fit: 431), a chunk extension is at most
// max_chunk_extension_bytes (400), and the bytes one request may take in all (request
// line, fields, chunk framing, body, trailers) are max_header_bytes twice plus
// max_body_bytes (413). The loop feeds the parser itself (parser.put()), so what the
// parser throws (basic_fields' "field value too large" for a field of 65,534 bytes or
// more) is caught here: 431, never io_context::run.
#include <algorithm>
#include <chrono>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <boost/asio/dispatch.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/error.hpp>
#include <boost/beast/http/parser.hpp>
#include <boost/beast/http/write.hpp>
#include <boost/beast/websocket/rfc6455.hpp>

#include "server/metrics/metrics.hpp"
#include "web/api.hpp"
#include "web/sessions.hpp"

namespace fins::web {

namespace {

using Request = http::request<http::string_body>;
using Response = http::response<http::string_body>;

// Room in the read buffer beyond the header limit: the start of a body or of the next
// pipelined request read together with a header.
constexpr std::size_t read_slack = 4 * 1024;
// Longest chunk extension (";name=value..." after a chunk's size): none is in use.
constexpr std::size_t max_chunk_extension_bytes = 256;

std::optional<std::string_view> header(const Request& r, http::field f) {
    const auto it = r.find(f);
    if (it == r.end()) return std::nullopt;
    return std::string_view(it->value().data(), it->value().size());
}

class HttpSession : public Connection, public std::enable_shared_from_this<HttpSession> {
  public:
    HttpSession(asio::ip::tcp::socket socket, std::shared_ptr<ServerShared> shared)
        : stream_(std::move(socket)),
          shared_(std::move(shared)),
          buffer_(options().max_header_bytes + read_slack) {}

    void start() {
        asio::dispatch(stream_.get_executor(), [self = shared_from_this()] {
            self->guard("HTTP read", [&] { self->read(); });
        });
    }

    void close() override {
        open_ = false;
        beast::error_code ignored;
        stream_.socket().shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
        stream_.close();
    }

  private:
    const WebOptions& options() const { return shared_->context.options; }

    // The failure boundary: an exception answers 500 and closes (or only closes when an
    // answer is already being written).
    template <class F>
    void guard(std::string_view where, F&& f) {
        guarded(*shared_, where, std::forward<F>(f), [this]() noexcept {
            try {
                if (open_ && !response_) return fail(500, "internal error: see finsd's log");
            } catch (...) {
            }
            close();
        });
    }

    std::size_t request_budget() const {
        return 2 * options().max_header_bytes + options().max_body_bytes;
    }

    void read() {
        if (!open_ || shared_->stopped) return;
        parser_.emplace();
        parser_->body_limit(options().max_body_bytes);
        parser_->header_limit(static_cast<std::uint32_t>(options().max_header_bytes));
        parser_->on_chunk_header(on_chunk_header_);
        consumed_ = 0;
        // The first request has the request deadline; later ones the idle one first.
        stream_.expires_after(requests_ == 0 ? options().request_timeout : options().idle_timeout);
        parse();
    }

    // Feeds the buffered bytes to the parser; reads more while it needs more.
    void parse() {
        while (buffer_.size() > 0 && !parser_->is_done()) {
            beast::error_code ec;
            std::size_t used = 0;
            try {
                used = parser_->put(buffer_.data(), ec);
            } catch (const std::length_error&) {
                return fail(431, "a header or trailer field is larger than the parser takes");
            }
            buffer_.consume(used);
            consumed_ += used;
            if (consumed_ > request_budget())
                return fail(413, "the request is larger than " + std::to_string(request_budget()) +
                                     " bytes (header, chunk framing, body and trailers)");
            if (ec == http::error::need_more) break;
            if (ec) return on_error(ec);
            if (used == 0) break;
        }
        if (parser_->is_done()) return on_request();
        read_more();
    }

    void read_more() {
        const std::size_t room = buffer_.max_size() - buffer_.size();
        if (room == 0)
            return fail(431, parser_->is_header_done()
                                 ? "a chunk header or the trailer is larger than " +
                                       std::to_string(buffer_.max_size()) + " bytes"
                                 : "the request's header is larger than " +
                                       std::to_string(options().max_header_bytes) + " bytes");
        if (parser_->got_some() && !timed_) {
            // A begun request has the request deadline from its first byte: a trickle
            // cannot hold the connection.
            stream_.expires_after(options().request_timeout);
            timed_ = true;
        }
        stream_.async_read_some(buffer_.prepare(std::min<std::size_t>(room, 16 * 1024)),
                                [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                                    self->guard("HTTP read", [&] { self->on_bytes(ec, n); });
                                });
    }

    void on_bytes(beast::error_code ec, std::size_t n) {
        if (!open_ || shared_->stopped) return;
        buffer_.commit(n);
        if (ec == asio::error::eof && parser_->got_some()) {
            beast::error_code eof;
            parser_->put_eof(eof);
            if (eof) return on_error(eof);
            return on_request();
        }
        if (ec) return close();  // eof, reset, timeout, aborted: nothing to answer
        parse();
    }

    void on_error(beast::error_code ec) {
        if (ec == http::error::header_limit)
            return fail(431, "the request's header is larger than " +
                                 std::to_string(options().max_header_bytes) + " bytes");
        if (ec == http::error::body_limit)
            return fail(413, "the request's body is larger than " +
                                 std::to_string(options().max_body_bytes) + " bytes");
        if (extension_too_long_)
            return fail(400, "a chunk extension is longer than " +
                                 std::to_string(max_chunk_extension_bytes) + " bytes");
        return fail(400, "malformed HTTP request: " + ec.message());
    }

    void on_request() {
        timed_ = false;
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
            upgrade,
            header(request, http::field::content_type)};
        if (auto refused = check_request(options(), meta))
            return answer(request, std::move(*refused));
        if (upgrade) {
            if (request.target() != "/ws")
                return answer(request, error_answer(404, "WebSocket is at /ws"));
            open_ = false;  // the WebSocket session owns the stream now
            stream_.expires_never();
            return run_websocket_session(std::move(stream_), std::move(request), shared_);
        }
        if (shared_->context.fault) shared_->context.fault("http request");
        const std::string_view body = request.body();
        handle_request(shared_->context, meta.method, meta.target, body,
                       [self = shared_from_this(), request](HttpAnswer a) {
                           self->guard("HTTP answer", [&] {
                               if (!self->open_ || self->shared_->stopped) return;
                               self->answer(request, std::move(a));
                           });
                       });
    }

    // An error the request cannot recover from: answer and close.
    void fail(unsigned status, std::string message) {
        Request none;
        none.keep_alive(false);
        answer(none, error_answer(status, message));
    }

    void answer(const Request& request, HttpAnswer a) {
        if (response_) return;  // one answer per request (a late callback after a 500)
        server::metrics::note_http_request(a.status);
        response_.emplace(static_cast<http::status>(a.status),
                          request.version() ? request.version() : 11);
        set_common_headers(*response_);
        response_->set(http::field::content_type, a.content_type);
        response_->keep_alive(request.keep_alive() && a.status < 500);
        if (request.method() != http::verb::head) response_->body() = std::move(a.body);
        response_->prepare_payload();
        stream_.expires_after(options().request_timeout);
        http::async_write(stream_, *response_,
                          [self = shared_from_this()](beast::error_code ec, std::size_t) {
                              self->guard("HTTP write", [&] {
                                  const bool again = !ec && self->response_->keep_alive();
                                  self->response_.reset();
                                  if (!again) return self->close();
                                  self->read();
                              });
                          });
    }

    beast::tcp_stream stream_;
    std::shared_ptr<ServerShared> shared_;
    beast::flat_buffer buffer_;  // at most max_header_bytes + read_slack unparsed bytes
    std::optional<http::request_parser<http::string_body>> parser_;
    std::function<void(std::uint64_t, beast::string_view, beast::error_code&)> on_chunk_header_ =
        [this](std::uint64_t, beast::string_view extensions, beast::error_code& ec) {
            if (extensions.size() > max_chunk_extension_bytes) {
                extension_too_long_ = true;
                ec = http::error::bad_chunk_extension;
            }
        };
    std::optional<Response> response_;
    std::size_t consumed_ = 0;  // bytes of this request the parser took
    std::size_t requests_ = 0;
    bool timed_ = false;  // this request's deadline is set
    bool extension_too_long_ = false;
    bool open_ = true;
};

}  // namespace

void run_http_session(asio::ip::tcp::socket socket, std::shared_ptr<ServerShared> shared) {
    auto session = std::make_shared<HttpSession>(std::move(socket), shared);
    shared->connections.push_back(session);
    session->start();
}

}  // namespace fins::web
