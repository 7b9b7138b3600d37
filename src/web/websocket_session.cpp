// One WebSocket connection (http_server.hpp): the subscriptions of one client
// (subscriptions.hpp) over a Beast websocket stream, polled every min_interval while it
// has any (an idle page costs nothing), with a bounded send queue.
//
// A slow client: when max_queued_messages are waiting, the queue is dropped (the message
// being written finishes) and every subscription sends a fresh snapshot next, so the
// client skips what it could not take and is exact again (seq shows the gap).
#include <chrono>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/websocket/stream.hpp>

#include "server/metrics/metrics.hpp"
#include "web/sessions.hpp"

namespace fins::web {

namespace {

namespace websocket = beast::websocket;

class WebSocketSession : public Connection, public std::enable_shared_from_this<WebSocketSession> {
  public:
    WebSocketSession(beast::tcp_stream stream, std::shared_ptr<ServerShared> shared)
        : ws_(std::move(stream)),
          timer_(ws_.get_executor()),
          shared_(std::move(shared)),
          subs_(std::make_unique<Subscriptions>(shared_->context, new_session_id())) {}

    void start(http::request<http::string_body> request) {
        ++shared_->websockets;
        ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
        ws_.set_option(websocket::stream_base::decorator(
            [](websocket::response_type& r) { set_common_headers(r); }));
        ws_.read_message_max(shared_->context.options.max_ws_message_bytes);
        ws_.text(true);
        ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
            if (ec) return self->close();
            self->queue(self->subs_->hello());
            self->read();
        });
    }

    ~WebSocketSession() override {
        --shared_->websockets;
        if (!shared_->stopped && subs_ != nullptr && subs_->size() > 0)
            shared_->resumable.keep(std::move(subs_), std::chrono::steady_clock::now());
    }

    void close() override {
        if (!open_) return;
        open_ = false;
        timer_.cancel();
        beast::get_lowest_layer(ws_).close();
    }

  private:
    void read() {
        ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
            self->on_read(ec);
        });
    }

    void on_read(beast::error_code ec) {
        if (ec || !open_ || shared_->stopped) return close();
        const auto data = buffer_.data();
        const std::string_view text(static_cast<const char*>(data.data()), data.size());
        std::vector<std::string> out;
        const auto resume = subs_->on_message(text, out);
        buffer_.consume(buffer_.size());
        if (resume) take_over(*resume, out);
        for (auto& m : out)
            queue(std::move(m));
        arm_poll();
        read();
    }

    // A reconnecting page asks for the subscriptions of its earlier connection.
    void take_over(const ResumeRequest& r, std::vector<std::string>& out) {
        const auto now = std::chrono::steady_clock::now();
        auto old = shared_->resumable.take(r.session, now);
        if (old == nullptr) {
            out.push_back(nlohmann::json{{"type", "resume_failed"},
                                         {"error", "unknown or expired session: subscribe again"}}
                              .dump());
            return;
        }
        subs_ = std::move(old);
        std::vector<std::string> replay;
        const bool complete = subs_->replay_after(r.seq, replay);
        out.push_back(nlohmann::json{
            {"type", "resumed"},
            {"session", subs_->session()},
            {"seq", subs_->seq()},
            {"replayed", replay.size()},
            {"snapshots",
             !complete}}.dump());
        for (auto& m : replay)
            out.push_back(std::move(m));
    }

    void arm_poll() {
        if (polling_ || !open_ || subs_->size() == 0) return;
        polling_ = true;
        timer_.expires_after(shared_->context.options.min_interval);
        timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
            self->polling_ = false;
            if (ec || !self->open_ || self->shared_->stopped) return;
            std::vector<std::string> out;
            self->subs_->poll(std::chrono::steady_clock::now(), std::chrono::system_clock::now(),
                              out);
            for (auto& m : out)
                self->queue(std::move(m));
            self->arm_poll();
        });
    }

    void queue(std::string message) {
        if (!open_) return;
        // The one being written stays; the rest is dropped for fresh snapshots.
        if (queue_.size() > shared_->context.options.max_queued_messages) {
            queue_.erase(queue_.begin() + (writing_ ? 1 : 0), queue_.end());
            subs_->resync();
            server::metrics::note_websocket_resync();
        }
        queue_.push_back(std::move(message));
        if (!writing_) write();
    }

    void write() {
        writing_ = true;
        ws_.async_write(asio::buffer(queue_.front()),
                        [self = shared_from_this()](beast::error_code ec, std::size_t) {
                            self->writing_ = false;
                            if (ec || !self->open_) return self->close();
                            self->queue_.pop_front();
                            if (!self->queue_.empty()) self->write();
                        });
    }

    websocket::stream<beast::tcp_stream> ws_;
    asio::steady_timer timer_;
    beast::flat_buffer buffer_;
    std::shared_ptr<ServerShared> shared_;
    std::unique_ptr<Subscriptions> subs_;
    std::deque<std::string> queue_;
    bool open_ = true;
    bool writing_ = false;
    bool polling_ = false;
};

}  // namespace

void run_websocket_session(beast::tcp_stream stream, http::request<http::string_body> request,
                           std::shared_ptr<ServerShared> shared) {
    auto session = std::make_shared<WebSocketSession>(std::move(stream), shared);
    shared->connections.push_back(session);
    session->start(std::move(request));
}

}  // namespace fins::web
