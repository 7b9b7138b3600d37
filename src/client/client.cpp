// fins::Client core: the io_context, the transport, the request tracker and the one
// timer that follows the tracker's next deadline. See include/fins/client.hpp.
#include "fins/client.hpp"

#include <memory>
#include <utility>

#include <asio/io_context.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>

#include "client/request_tracker.hpp"
#include "transport/tcp_transport.hpp"
#include "transport/udp_transport.hpp"

namespace fins {

namespace {

SteadyTime now() {
    return std::chrono::steady_clock::now();
}

// UDP on loopback derives node 1 for both ends; a source equal to the destination would
// look like the PLC talking to itself (W421 7-4 refuses it on TCP with error 0x24).
constexpr std::uint8_t fallback_source_node = 254;

}  // namespace

struct Client::Impl final : FrameSink {
    explicit Impl(ClientOptions o)
        : options(std::move(o)), tracker(*this, options.gateway_count), timer(io) {
        transport::TransportOptions t;
        t.host = options.host;
        t.port = options.port;
        t.open_timeout = options.timeout;
        t.requested_node = options.source.node;
        if (options.protocol == ClientOptions::Protocol::tcp)
            transport = std::make_unique<transport::TcpTransport>(io, std::move(t));
        else
            transport = std::make_unique<transport::UdpTransport>(io, std::move(t));
        transport->set_frame_handler([this](Bytes frame) {
            tracker.on_frame(frame, now());
            rearm();
        });
        transport->set_close_handler([this](std::error_code reason) {
            tracker.link_down(reason);
            rearm();
        });
    }

    void send_frame(Bytes frame) override { transport->send(frame); }

    // Starts opening unless already open or opening; `notify` hears how this open ends.
    void ensure_open(std::function<void(std::error_code)> notify = nullptr) {
        if (transport->state() != transport::Transport::State::closed) return;
        transport->async_open([this, notify = std::move(notify)](Result<transport::LinkInfo> r) {
            if (!r) {
                last_open_error = r.error();
                tracker.link_down(r.error());
            } else {
                last_open_error.clear();
                ++opens;
                tracker.link_up(derive_destination(*r), derive_source(*r), now());
            }
            rearm();
            if (notify) notify(r ? std::error_code{} : r.error());
        });
    }

    NodeAddress derive_destination(const transport::LinkInfo& info) const {
        NodeAddress d = options.destination;
        if (d.node == 0) d.node = info.remote_node;
        return d;
    }

    NodeAddress derive_source(const transport::LinkInfo& info) const {
        NodeAddress s = options.source;
        if (options.protocol == ClientOptions::Protocol::tcp) {
            // The server's answer is authoritative (it may have allocated the node).
            s.node = info.local_node;
            return s;
        }
        if (s.node == 0) {
            s.node = info.local_node;
            auto d = derive_destination(info);
            if (s.node == d.node)
                s.node = d.node == fallback_source_node ? fallback_source_node - 1
                                                        : fallback_source_node;
        }
        return s;
    }

    void rearm() {
        auto next = tracker.next_deadline();
        if (next == armed) return;
        armed = next;
        auto gen = ++timer_generation;
        if (!next) {
            timer.cancel();
            return;
        }
        timer.expires_at(*next);
        timer.async_wait([this, gen](std::error_code ec) {
            if (ec || gen != timer_generation) return;
            armed.reset();
            tracker.on_timer(now());
            rearm();
        });
    }

    [[nodiscard]] RequestTiming timing() const { return {options.timeout, options.retries}; }

    // Declaration order is destruction order in reverse: the io_context goes last, so
    // no handler that refers to the members below can run after they are gone.
    asio::io_context io;
    ClientOptions options;
    std::unique_ptr<transport::Transport> transport;
    RequestTracker tracker;
    asio::steady_timer timer;
    std::optional<SteadyTime> armed;
    std::uint64_t timer_generation = 0;
    std::uint64_t opens = 0;
    std::size_t posted = 0;  // failures posted by fail_later() and not yet delivered
    std::error_code last_open_error;
};

Client::Client(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Client::~Client() {
    if (impl_) impl_->transport->close();
}

Result<std::unique_ptr<Client>> Client::connect(ClientOptions options) {
    if (options.retries > max_retries)
        return Unexpected(make_error_code(ClientError::invalid_argument));
    if (options.timeout.count() <= 0) options.timeout = default_timeout;
    std::unique_ptr<Client> client(new Client(std::make_unique<Impl>(std::move(options))));
    std::optional<std::error_code> opened;
    client->impl_->ensure_open([&opened](std::error_code ec) { opened = ec; });
    client->run_until([&opened] { return opened.has_value(); });
    if (!opened) return Unexpected(make_error_code(ClientError::not_connected));
    if (*opened) return Unexpected(*opened);
    return client;
}

void Client::submit(CommandCode code, Bytes parameters, ViewCompletion done) {
    auto& i = *impl_;
    // The tracker takes `done` only on success; on failure it is untouched and still ours.
    auto id = i.tracker.submit(code, parameters, i.timing(), std::move(done), now());
    if (!id) return fail_later(std::move(done), id.error());
    if (!i.tracker.is_link_up()) i.ensure_open();
    i.rearm();
}

void Client::fail_later(ViewCompletion done, std::error_code ec) {
    auto* impl = impl_.get();
    ++impl->posted;
    asio::post(impl->io, [impl, done = std::move(done), ec] {
        --impl->posted;
        done(Unexpected(ec));
    });
}

Result<void> Client::submit_no_response(CommandCode code, Bytes parameters) {
    auto& i = *impl_;
    if (!i.tracker.is_link_up()) {
        i.ensure_open();
        run_until([&i] {
            return i.tracker.is_link_up() ||
                   i.transport->state() == transport::Transport::State::closed;
        });
        if (!i.tracker.is_link_up())
            return Unexpected(i.last_open_error ? i.last_open_error
                                                : make_error_code(ClientError::not_connected));
    }
    auto id = i.tracker.submit_no_response(code, parameters);
    if (!id) return Unexpected(id.error());
    if (!i.transport->write_pending()) return {};
    // Nothing confirms a no-response frame: wait only until the kernel has it.
    auto expired = std::make_shared<bool>(false);
    asio::steady_timer flush(i.io, i.options.timeout);
    flush.async_wait([expired](std::error_code ec) { *expired = !ec; });
    run_until([&] { return *expired || !i.transport->write_pending(); });
    if (i.transport->write_pending()) return Unexpected(make_error_code(ClientError::timeout));
    return {};
}

Result<void> Client::send_no_response(CommandCode code, Bytes parameters) {
    return submit_no_response(code, parameters);
}

void Client::run_until(const std::function<bool()>& done) {
    auto& io = impl_->io;
    // Every request ends by its deadline, and the open and flush waits have timers, so
    // run_one() always has something to wait for; the idle guard only ensures that a
    // broken invariant ends the wait instead of hanging.
    int idle = 0;
    while (!done()) {
        if (io.stopped()) io.restart();
        if (io.run_one() > 0) {
            idle = 0;
            continue;
        }
        io.restart();
        if (++idle == 2) impl_->tracker.cancel_all(make_error_code(ClientError::canceled));
        if (idle > 2) return;
    }
    // Also run whatever is ready right now (e.g. completions queued behind ours).
    if (io.stopped()) io.restart();
    io.poll();
}

void Client::run() {
    auto& i = *impl_;
    run_until([&i] { return i.tracker.in_flight() == 0 && i.posted == 0; });
}

Result<RawResponse> Client::send_raw(CommandCode code, Bytes parameters) {
    std::optional<Result<RawResponse>> out;
    async_send_raw(code, parameters, [&out](Result<RawResponse> r) { out.emplace(std::move(r)); });
    run_until([&out] { return out.has_value(); });
    if (!out) return Unexpected(make_error_code(ClientError::canceled));
    return std::move(*out);
}

void Client::async_send_raw(CommandCode code, Bytes parameters,
                            std::function<void(Result<RawResponse>)> done) {
    submit(code, parameters, [done = std::move(done)](Result<ResponseView> r) {
        if (!r) return done(Unexpected(r.error()));
        RawResponse raw;
        raw.header = r->header;
        raw.command = r->command;
        raw.code = r->code;
        raw.relay = r->relay;
        raw.data.assign(r->data.begin(), r->data.end());
        done(std::move(raw));
    });
}

ClientStats Client::stats() const noexcept {
    const auto& s = impl_->tracker.stats();
    ClientStats out;
    out.sent = s.sent;
    out.retransmitted = s.retransmitted;
    out.completed = s.completed;
    out.timed_out = s.timed_out;
    out.failed = s.failed;
    out.stale_discarded = s.stale_discarded;
    out.invalid_discarded = s.invalid_discarded;
    out.reconnects = impl_->opens > 0 ? impl_->opens - 1 : 0;
    return out;
}

std::size_t Client::in_flight() const noexcept {
    return impl_->tracker.in_flight();
}
bool Client::is_connected() const noexcept {
    return impl_->tracker.is_link_up();
}
const ClientOptions& Client::options() const noexcept {
    return impl_->options;
}
NodeAddress Client::destination() const noexcept {
    return impl_->tracker.destination();
}
NodeAddress Client::source() const noexcept {
    return impl_->tracker.source();
}

void Client::close() {
    impl_->transport->close();
    impl_->tracker.link_down(make_error_code(ClientError::canceled));
    impl_->rearm();
}

}  // namespace fins
