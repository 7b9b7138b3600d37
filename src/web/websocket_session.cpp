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
#include <algorithm>
#include <array>
#include <chrono>
#include <deque>
#include <iterator>
#include <list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <boost/asio/post.hpp>
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
        // Pings count against the message budget (Beast answers each with a pong).
        ws_.control_callback([this](websocket::frame_type kind, beast::string_view) {
            if (kind == websocket::frame_type::ping) spend();
        });
        ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
            self->guard("WebSocket accept", [&] {
                if (ec) return self->close();
                self->queue(Message{self->subs_->hello(), nullptr});
                self->read();
            });
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
    // The failure boundary: an exception closes this connection (the server goes on).
    template <class F>
    void guard(std::string_view where, F&& f) {
        guarded(*shared_, where, std::forward<F>(f), [this]() noexcept { close(); });
    }

    // One client message or ping against the budget: max_ws_messages_per_second, with a
    // burst of as many. Beyond it the connection is closed with 1008 (policy violation):
    // a flood costs the I/O thread (and FINS) at most that rate.
    void spend() {
        if (policy_closing_) return;
        const auto now = std::chrono::steady_clock::now();
        const auto rate = static_cast<double>(shared_->context.options.max_ws_messages_per_second);
        tokens_ =
            std::min(rate, tokens_ + rate * std::chrono::duration<double>(now - filled_).count());
        filled_ = now;
        if (tokens_ >= 1) {
            tokens_ -= 1;
            return;
        }
        policy_closing_ = true;
        server::metrics::note_websocket_policy_close();
        asio::post(ws_.get_executor(), [self = shared_from_this()] {
            self->guard("WebSocket close", [&] {
                if (!self->open_) return;
                // A flooder that does not answer the close is not waited for long.
                auto timeouts =
                    websocket::stream_base::timeout::suggested(beast::role_type::server);
                timeouts.handshake_timeout = std::chrono::seconds(1);
                timeouts.idle_timeout = self->shared_->context.options.websocket_idle_timeout;
                self->ws_.set_option(timeouts);
                self->ws_.async_close(
                    websocket::close_reason(websocket::close_code::policy_error,
                                            "more than the message budget per second"),
                    [self](beast::error_code) { self->close(); });
            });
        });
    }

    void read() {
        ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
            self->guard("WebSocket message", [&] { self->on_read(ec); });
        });
    }

    void on_read(beast::error_code ec) {
        if (ec || !open_ || shared_->stopped) return close();
        spend();
        if (policy_closing_) return;  // the close goes out; nothing more is read
        const auto data = buffer_.data();
        const std::string_view text(static_cast<const char*>(data.data()), data.size());
        std::vector<Message> out;
        if (shared_->context.fault) shared_->context.fault("websocket message");
        const auto resume = subs_->on_message(text, out);
        buffer_.consume(buffer_.size());
        if (resume) take_over(*resume, out);
        // A new subscription's snapshot goes out now, not at the next tick (within what is
        // left of this connection's budget until the next tick).
        subs_->poll(std::chrono::steady_clock::now(), std::chrono::system_clock::now(), out,
                    between_ticks_);
        for (auto& m : out)
            queue(std::move(m));
        if (subs_->size() > 0) arm_tick(shared_);
        read();
    }

    bool poll(SteadyTime now, std::chrono::system_clock::time_point wall,
              std::size_t& budget) override {
        if (!open_ || subs_->size() == 0) return false;
        const std::size_t share = shared_->context.options.max_ws_words_per_tick_per_connection;
        between_ticks_ = share;
        guard("WebSocket poll", [&] {
            if (shared_->context.fault) shared_->context.fault("websocket poll");
            out_.clear();
            std::size_t mine = std::min(share, budget);
            const std::size_t given = mine;
            subs_->poll(now, wall, out_, mine);
            budget -= given - mine;
            for (auto& m : out_)
                queue(std::move(m));
        });
        return open_;
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
        if (!open_ || policy_closing_) return;
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
            self->guard("WebSocket write", [&] {
                self->writing_ = false;
                if (ec || !self->open_) return self->close();
                self->queue_.pop_front();
                if (!self->queue_.empty() && !self->policy_closing_) self->write();
            });
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
    double tokens_ = 0;  // the message budget left (spend())
    // Words this connection's messages may still refresh before the next tick.
    std::size_t between_ticks_ = shared_->context.options.max_ws_words_per_tick_per_connection;
    SteadyTime filled_{};
    bool policy_closing_ = false;
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
        bool any = false;
        std::list<std::weak_ptr<Connection>> served;
        guarded(
            *self, "WebSocket tick",
            [&] {
                const auto now = std::chrono::steady_clock::now();
                const auto wall = std::chrono::system_clock::now();
                // Round-robin: connections the budget did not reach this tick come first
                // at the next one (those served move to the end, in order).
                std::size_t budget = self->context.options.max_ws_words_per_tick;
                auto& list = self->connections;
                for (auto it = list.begin(); it != list.end();) {
                    const auto c = it->lock();
                    if (c == nullptr || budget == 0) {
                        any = any || c != nullptr;  // waiting: poll again next tick
                        ++it;
                        continue;
                    }
                    any = c->poll(now, wall, budget) || any;
                    const auto next = std::next(it);
                    served.splice(served.end(), list, it);
                    it = next;
                }
            },
            [&]() noexcept { any = true; });
        self->connections.splice(self->connections.end(), served);
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
