// fins::Client core: opening, submitting, running the io_context. See
// include/fins/client.hpp and client/client_impl.hpp.
#include "fins/client.hpp"

#include <memory>
#include <string>
#include <utility>

#include <boost/asio/post.hpp>

#include "client/client_impl.hpp"
#include "transport/asio.hpp"

namespace fins {

Client::Client(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Client::~Client() {
    if (impl_) impl_->transport->close();
}

namespace {

// The checks and defaults both ways of making a client share.
Result<ClientOptions> checked(ClientOptions options) {
    if (options.retries > max_retries || (options.protocol == ClientOptions::Protocol::serial &&
                                          options.host_link_unit > host_link_max_unit))
        return Unexpected(make_error_code(ClientError::invalid_argument));
    if (options.timeout.count() <= 0) options.timeout = default_timeout;
    return options;
}

}  // namespace

Result<std::unique_ptr<Client>> Client::create(asio::io_context& io, ClientOptions options) {
    auto o = checked(std::move(options));
    if (!o) return Unexpected(o.error());
    return std::unique_ptr<Client>(new Client(std::make_unique<Impl>(std::move(*o), &io)));
}

void Client::async_open(std::function<void(std::error_code)> done) {
    auto& i = *impl_;
    i.check_idle_link();
    if (i.tracker.is_link_up()) {
        std::weak_ptr<int> life = i.life;
        asio::post(i.io, [life, done = std::move(done)] {
            if (!life.expired()) done({});
        });
        return;
    }
    i.ensure_open(std::move(done));
}

Result<std::unique_ptr<Client>> Client::connect(ClientOptions options) {
    auto o = checked(std::move(options));
    if (!o) return Unexpected(o.error());
    std::unique_ptr<Client> client(new Client(std::make_unique<Impl>(std::move(*o), nullptr)));
    std::optional<std::error_code> opened;
    client->impl_->ensure_open([&opened](std::error_code ec) { opened = ec; });
    client->run_until([&opened] { return opened.has_value(); });
    if (!opened) return Unexpected(make_error_code(ClientError::not_connected));
    if (*opened) return Unexpected(*opened);
    return client;
}

void Client::submit(CommandCode code, Bytes parameters, ViewCompletion done) {
    auto& i = *impl_;
    i.check_idle_link();
    const auto t = now();
    // The tracker takes `done` only on success; on failure it is untouched and still ours.
    auto ok = i.tracker.submit(code, parameters, i.timing(), std::move(done), t);
    if (!ok) return fail_later(std::move(done), ok.error());
    if (!i.tracker.is_link_up()) i.ensure_open();
    if (i.tracker.waiting() > 0)
        i.rearm();  // a quarantine may end before the deadline
    else
        i.arm_by(t + i.options.timeout);
}

bool Client::in_callback() const noexcept {
    return impl_->embedded || impl_->running > 0;
}

void Client::fail_later(ViewCompletion done, std::error_code ec) {
    auto* impl = impl_.get();
    ++impl->posted;
    std::weak_ptr<int> life = impl->life;
    asio::post(impl->io, [impl, life, done = std::move(done), ec] {
        if (life.expired()) return;  // the client is gone (embedded): no callback
        --impl->posted;
        done(Unexpected(ec));
    });
}

Result<void> Client::submit_no_response(CommandCode code, Bytes parameters) {
    auto& i = *impl_;
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    i.check_idle_link();
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
    // `running` tells the synchronous calls that they are inside a handler.
    struct Running {
        int& depth;
        explicit Running(int& d) : depth(d) { ++depth; }
        ~Running() { --depth; }
        Running(const Running&) = delete;
        Running& operator=(const Running&) = delete;
    };
    int idle = 0;
    while (!done()) {
        if (io.stopped()) io.restart();
        std::size_t ran = 0;
        {
            Running r(impl_->running);
            ran = io.run_one();
        }
        if (ran > 0) {
            idle = 0;
            continue;
        }
        io.restart();
        if (++idle == 2) impl_->tracker.cancel_all(make_error_code(ClientError::canceled), now());
        if (idle > 2) return;
    }
    // Also run whatever is ready right now (e.g. completions queued behind ours).
    if (io.stopped()) io.restart();
    Running r(impl_->running);
    io.poll();
}

void Client::run() {
    auto& i = *impl_;
    if (in_callback()) return;  // documented: a no-op inside a completion callback
    run_until([&i] { return i.tracker.in_flight() == 0 && i.posted == 0; });
}

Result<RawResponse> Client::send_raw(CommandCode code, Bytes parameters) {
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    std::optional<Result<RawResponse>> out;
    async_send_raw(code, parameters, [&out](Result<RawResponse> r) { out.emplace(std::move(r)); });
    run_until([&out] { return out.has_value(); });
    if (!out) return Unexpected(make_error_code(ClientError::canceled));
    return std::move(*out);
}

void Client::async_send_view(CommandCode code, Bytes parameters,
                             std::function<void(Result<ResponseView>)> done) {
    submit(code, parameters, std::move(done));
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
    out.other_node_answers = s.other_node_answers;
    out.reconnects = impl_->opens > 0 ? impl_->opens - 1 : 0;
    out.quarantined = s.quarantined;
    out.waited_for_id = s.waited_for_id;
    out.quarantine_raised = s.quarantine_raised;
    return out;
}

std::string endpoint_name(const ClientOptions& options) {
    if (options.protocol == ClientOptions::Protocol::serial)
        return options.serial.device + " unit " + std::to_string(options.host_link_unit);
    const bool v6_literal = options.host.find(':') != std::string::npos;
    return (v6_literal ? "[" + options.host + "]" : options.host) + ":" +
           std::to_string(options.port);
}

std::string describe_error(const ClientOptions& options, std::error_code ec) {
    auto message = ec.message();
    // strerror() capitalises ("Connection refused"); the library's own texts do not, and
    // an acronym ("FINS/TCP ...") is left alone.
    if (message.size() > 1 && message[0] >= 'A' && message[0] <= 'Z' && message[1] >= 'a' &&
        message[1] <= 'z')
        message[0] = static_cast<char>(message[0] - 'A' + 'a');
    return endpoint_name(options) + ": " + message;
}

std::string Client::describe(std::error_code ec) const {
    return describe_error(impl_->options, ec);
}

std::size_t Client::max_parameters() const noexcept {
    return impl_->options.protocol == ClientOptions::Protocol::serial
               ? host_link_max_parameter_bytes
               : max_parameter_size;
}
std::size_t Client::max_response_data() const noexcept {
    return impl_->options.protocol == ClientOptions::Protocol::serial
               ? host_link_max_response_data_bytes
               : max_response_data_size;
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
std::optional<NodeAddress> Client::other_node() const noexcept {
    return impl_->tracker.other_node();
}

void Client::close() {
    impl_->transport->close();
    impl_->tracker.link_down(make_error_code(ClientError::canceled));
    impl_->rearm();
}

}  // namespace fins
