// One WebSocket connection (http_server.hpp): the subscriptions of one client
// (subscriptions.hpp) over a Beast websocket stream, polled by the server's one tick
// every min_interval while any connection has subscriptions (an idle page costs
// nothing), and at once after a subscribe (its snapshot does not wait for the tick), with
// a bounded send queue of messages whose values are shared between connections.
// Keep-alive: Beast pings a client that sent nothing for half of
// WebOptions::websocket_idle_timeout and closes one that does not answer by its end.
//
// A slow client: when max_queued_messages are waiting, the queue is dropped (the message
// being written finishes) and every subscription sends a fresh snapshot next, so the
// client skips what it could not take and is exact again (seq shows the gap).
#include <array>
#include <chrono>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

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
          shared_(std::move(shared)),
          subs_(std::make_unique<Subscriptions>(shared_->context, new_session_id())) {}

    void start(http::request<http::string_body> request) {
        ++shared_->websockets;
        auto timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
        timeouts.idle_timeout = shared_->context.options.websocket_idle_timeout;
        timeouts.keep_alive_pings = true;
        ws_.set_option(timeouts);
        ws_.set_option(websocket::stream_base::decorator(
            [](websocket::response_type& r) { set_common_headers(r); }));
        ws_.read_message_max(shared_->context.options.max_ws_message_bytes);
        ws_.text(true);
        ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
            if (ec) return self->close();
            self->queue(Message{self->subs_->hello(), nullptr});
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
        std::vector<Message> out;
        const auto resume = subs_->on_message(text, out);
        buffer_.consume(buffer_.size());
        if (resume) take_over(*resume, out);
        // A new subscription's snapshot goes out now, not at the next tick.
        subs_->poll(std::chrono::steady_clock::now(), std::chrono::system_clock::now(), out);
        for (auto& m : out)
            queue(std::move(m));
        if (subs_->size() > 0) arm_tick(shared_);
        read();
    }

    bool poll(SteadyTime now, std::chrono::system_clock::time_point wall) override {
        if (!open_ || subs_->size() == 0) return false;
        out_.clear();
        subs_->poll(now, wall, out_);
        for (auto& m : out_)
            queue(std::move(m));
        return true;
    }

    // A reconnecting page asks for the subscriptions of its earlier connection.
    void take_over(const ResumeRequest& r, std::vector<Message>& out) {
        const auto now = std::chrono::steady_clock::now();
        auto old = shared_->resumable.take(r.session, now);
        if (old == nullptr) {
            out.push_back(
                Message{nlohmann::json{{"type", "resume_failed"},
                                       {"error", "unknown or expired session: subscribe again"}}
                            .dump(),
                        nullptr});
            return;
        }
        subs_ = std::move(old);
        std::vector<Message> replay;
        const bool complete = subs_->replay_after(r.seq, replay);
        out.push_back(Message{nlohmann::json{{"type", "resumed"},
                                             {"session", subs_->session()},
                                             {"seq", subs_->seq()},
                                             {"replayed", replay.size()},
                                             {"snapshots", !complete}}
                                  .dump(),
                              nullptr});
        for (auto& m : replay)
            out.push_back(std::move(m));
    }

    void queue(Message message) {
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
        const Message& m = queue_.front();
        static constexpr char close_brace = '}';
        std::array<asio::const_buffer, 3> buffers{asio::buffer(m.head), asio::const_buffer{},
                                                  asio::const_buffer{}};
        if (m.body) {
            buffers[1] = asio::buffer(*m.body);
            buffers[2] = asio::buffer(&close_brace, 1);
        }
        ws_.async_write(buffers, [self = shared_from_this()](beast::error_code ec, std::size_t) {
            self->writing_ = false;
            if (ec || !self->open_) return self->close();
            self->queue_.pop_front();
            if (!self->queue_.empty()) self->write();
        });
    }

    websocket::stream<beast::tcp_stream> ws_;
    beast::flat_buffer buffer_;
    std::shared_ptr<ServerShared> shared_;
    std::unique_ptr<Subscriptions> subs_;
    std::deque<Message> queue_;
    std::vector<Message> out_;
    bool open_ = true;
    bool writing_ = false;
};

}  // namespace

void arm_tick(const std::shared_ptr<ServerShared>& shared) {
    if (shared->ticking || shared->stopped) return;
    shared->ticking = true;
    shared->tick.expires_after(shared->context.options.min_interval);
    shared->tick.async_wait([weak = std::weak_ptr<ServerShared>(shared)](beast::error_code ec) {
        const auto self = weak.lock();
        if (self == nullptr) return;
        self->ticking = false;
        if (ec || self->stopped) return;
        const auto now = std::chrono::steady_clock::now();
        const auto wall = std::chrono::system_clock::now();
        bool any = false;
        for (const auto& w : self->connections)
            if (const auto c = w.lock()) any = c->poll(now, wall) || any;
        if (any) arm_tick(self);  // no subscription anywhere: no timer (an idle server)
    });
}

void run_websocket_session(beast::tcp_stream stream, http::request<http::string_body> request,
                           std::shared_ptr<ServerShared> shared) {
    auto session = std::make_shared<WebSocketSession>(std::move(stream), shared);
    shared->connections.push_back(session);
    session->start(std::move(request));
}

}  // namespace fins::web
