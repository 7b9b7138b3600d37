#include "bridge/mqtt.hpp"

#include <mosquitto.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <random>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

namespace fins::bridge {

namespace {

void init_library() {
    static const int once = mosquitto_lib_init();
    (void)once;
}

std::uint64_t seed() {
    std::random_device r;
    return (std::uint64_t{r()} << 32) | r();
}

}  // namespace

MqttClient::MqttClient(asio::io_context& io, const Mqtt& config, Message will, Message online,
                       std::vector<std::string> subscriptions, Handlers handlers, bool persistent)
    : io_(io),
      config_(config),
      will_(std::move(will)),
      online_(std::move(online)),
      subscriptions_(std::move(subscriptions)),
      handlers_(std::move(handlers)),
      persistent_(persistent),
      misc_timer_(io),
      retry_timer_(io),
      resolver_(io),
      backoff_(config.backoff_min, config.backoff_max, seed()) {}

MqttClient::~MqttClient() {
    if (mosq_ != nullptr && !closing_) stop(will_);
    unwrap();
    if (mosq_ != nullptr) mosquitto_destroy(mosq_);
}

bool MqttClient::start(std::string& error) {
    init_library();
    // A persistent session keeps the subscriptions and the QoS 1 messages for them on the
    // broker while this client is away (clean_session = false).
    mosq_ = mosquitto_new(config_.client_id.c_str(), !persistent_, this);
    if (mosq_ == nullptr) {
        error = "mosquitto_new failed";
        return false;
    }
    // "Threaded" for libmosquitto means only that publish() queues and does not write: the
    // io_context writes what was queued when the socket is writable, all of it at once
    // (writable()), so that the messages of one turn of the loop share TCP segments.
    mosquitto_threaded_set(mosq_, true);
    mosquitto_int_option(mosq_, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
    mosquitto_int_option(mosq_, MOSQ_OPT_TCP_NODELAY, 1);
    mosquitto_connect_callback_set(mosq_, &MqttClient::on_connect);
    mosquitto_disconnect_callback_set(mosq_, &MqttClient::on_disconnect);
    mosquitto_publish_callback_set(mosq_, &MqttClient::on_publish);
    mosquitto_message_callback_set(mosq_, &MqttClient::on_message);
    int rc = mosquitto_will_set(mosq_, will_.topic.c_str(), static_cast<int>(will_.payload.size()),
                                will_.payload.data(), will_.qos, will_.retain);
    if (rc == MOSQ_ERR_SUCCESS && !config_.username.empty())
        rc = mosquitto_username_pw_set(
            mosq_, config_.username.c_str(),
            config_.password.empty() ? nullptr : config_.password.c_str());
    if (rc == MOSQ_ERR_SUCCESS && !config_.ca_file.empty()) {
        rc = mosquitto_tls_set(mosq_, config_.ca_file.c_str(), nullptr,
                               config_.cert_file.empty() ? nullptr : config_.cert_file.c_str(),
                               config_.key_file.empty() ? nullptr : config_.key_file.c_str(),
                               nullptr);
        if (rc == MOSQ_ERR_SUCCESS && config_.tls_insecure)
            rc = mosquitto_tls_insecure_set(mosq_, true);
    }
    if (rc != MOSQ_ERR_SUCCESS) {
        error = fmt::format("MQTT settings refused: {}", mosquitto_strerror(rc));
        return false;
    }
    connect();
    return true;
}

void MqttClient::connect() {
    retrying_ = false;
    if (closing_) return;
    const Broker& b = config_.brokers[broker_ % config_.brokers.size()];
    boost::system::error_code ec;
    (void)asio::ip::make_address(b.host, ec);
    untried_.clear();
    if (!ec) return connect_to(b.host, b.port);  // an address: nothing to look up
    const auto attempt = ++resolving_;
    looking_up_ = true;
    resolver_.async_resolve(
        b.host, std::to_string(b.port), asio::ip::tcp::resolver::numeric_service,
        [this, alive = std::weak_ptr<int>(alive_), attempt, host = b.host, port = b.port](
            boost::system::error_code error, const asio::ip::tcp::resolver::results_type& found) {
            if (alive.expired()) return;
            if (attempt == resolving_) looking_up_ = false;
            if (closing_ || attempt != resolving_) return;
            if (error || found.empty()) {
                spdlog::warn("MQTT broker {}:{}: {}", host, port,
                             error ? error.message() : "the name has no address");
                lost();  // a failed attempt: the next broker after the backoff
                return;
            }
            // TLS checks the broker's certificate against the name (and sends it as SNI).
            untried_.clear();
            if (!config_.ca_file.empty()) {
                untried_.push_back(host);
            } else {
                for (const auto& entry : found) {
                    auto address = entry.endpoint().address().to_string();
                    if (std::find(untried_.begin(), untried_.end(), address) == untried_.end())
                        untried_.push_back(std::move(address));
                }
            }
            std::reverse(untried_.begin(), untried_.end());  // taken from the back
            next_address(port);
        });
}

void MqttClient::next_address(std::uint16_t port) {
    auto host = std::move(untried_.back());
    untried_.pop_back();
    connect_to(host, port);
}

void MqttClient::connect_to(const std::string& host, std::uint16_t port) {
    accepted_ = false;
    if (handlers_.will && will_sent_) {
        will_ = handlers_.will();
        mosquitto_will_set(mosq_, will_.topic.c_str(), static_cast<int>(will_.payload.size()),
                           will_.payload.data(), will_.qos, will_.retain);
        will_sent_ = false;
    }
    ++generation_;
    // The old socket (if any) is closed by libmosquitto here and the new one may get its
    // number: stop watching it first.
    unwrap();
    const int rc = mosquitto_connect_async(mosq_, host.c_str(), port,
                                           static_cast<int>(config_.keepalive.count()));
    if (rc != MOSQ_ERR_SUCCESS)
        spdlog::warn("MQTT broker {}:{}: {}", host, port, mosquitto_strerror(rc));
    sync();
}

void MqttClient::unwrap() noexcept {
    if (socket_) {
        // Ends the waits (operation_aborted) without closing libmosquitto's socket.
        (void)socket_->release();
        socket_.reset();
    }
    fd_ = -1;
    ++wraps_;
    reading_ = false;
    writing_ = false;
}

void MqttClient::sync() {
    if (closing_ || mosq_ == nullptr) return;
    const int fd = mosquitto_socket(mosq_);
    if (fd != fd_) {
        unwrap();
        if (fd >= 0) {
            socket_.emplace(io_);
            boost::system::error_code ec;
            socket_->assign(fd, ec);
            if (ec) {
                spdlog::warn("MQTT socket cannot be watched: {}", ec.message());
                socket_.reset();
                mosquitto_disconnect(mosq_);
                lost();
                return;
            }
            fd_ = fd;
        }
    }
    if (fd < 0) {
        lost();
        return;
    }
    if (!reading_) wait_read();
    if (!writing_ && mosquitto_want_write(mosq_)) wait_write();
    if (!misc_armed_) misc();
}

void MqttClient::wait_read() {
    reading_ = true;
    socket_->async_wait(
        asio::posix::descriptor_base::wait_read,
        [this, alive = std::weak_ptr<int>(alive_), w = wraps_](boost::system::error_code ec) {
            if (alive.expired() || ec || w != wraps_) return;
            reading_ = false;
            readable();
        });
}

void MqttClient::wait_write() {
    writing_ = true;
    socket_->async_wait(
        asio::posix::descriptor_base::wait_write,
        [this, alive = std::weak_ptr<int>(alive_), w = wraps_](boost::system::error_code ec) {
            if (alive.expired() || ec || w != wraps_) return;
            writing_ = false;
            writable();
        });
}

void MqttClient::misc() {
    misc_armed_ = true;
    misc_timer_.expires_after(std::chrono::seconds(1));
    misc_timer_.async_wait(
        [this, alive = std::weak_ptr<int>(alive_)](boost::system::error_code ec) {
            if (alive.expired() || ec) return;
            misc_armed_ = false;
            if (closing_ || fd_ < 0) return;
            // Keepalive: PINGREQ when due; closes a connection whose broker went quiet (also an
            // attempt whose CONNACK did not come within the keepalive).
            mosquitto_loop_misc(mosq_);
            sync();
        });
}

void MqttClient::readable() {
    // Also drives the TLS handshake while it wants to read.
    mosquitto_loop_read(mosq_, 1);
    sync();
}

void MqttClient::writable() {
    // Before CONNACK a TLS handshake may wait for the socket to take its bytes: only
    // loop_read drives the handshake (loop_write waits for it to end), and it is harmless
    // when nothing is to be read.
    if (!accepted_ && !config_.ca_file.empty()) {
        mosquitto_loop_read(mosq_, 1);
        if (mosquitto_socket(mosq_) != fd_) return sync();
    }
    // Corked: the packets written now leave in as few segments as they fill (TCP_NODELAY
    // would send each on its own), and uncorking sends the rest at once.
    int on = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_CORK, &on, sizeof on);
    mosquitto_loop_write(mosq_, 1);
    if (const int fd = mosquitto_socket(mosq_); fd == fd_ && fd >= 0) {
        on = 0;
        ::setsockopt(fd, IPPROTO_TCP, TCP_CORK, &on, sizeof on);
        // Written, CONNECT included: its Will reached a broker (with TLS: once CONNACK says so;
        // until the handshake ends nothing is written).
        if (!will_sent_ && config_.ca_file.empty() && !mosquitto_want_write(mosq_))
            will_sent_ = true;
    }
    sync();
}

void MqttClient::lost() {
    unwrap();
    if (retrying_ || closing_) return;
    retrying_ = true;
    misc_timer_.cancel();
    misc_armed_ = false;
    connected_ = false;
    queued_ = 0;  // what libmosquitto held for the lost connection is gone
    const bool was_accepted = accepted_;
    accepted_ = false;
    if (!was_accepted && !untried_.empty()) {
        // The same broker's next address, at once (after this call returns).
        retrying_ = true;
        asio::post(io_, [this, alive = std::weak_ptr<int>(alive_)] {
            if (alive.expired() || closing_) return;
            retrying_ = false;
            if (untried_.empty()) return connect();
            next_address(config_.brokers[broker_ % config_.brokers.size()].port);
        });
        return;
    }
    untried_.clear();
    if (was_accepted) {
        backoff_.reset();  // a lost session: the same broker first
    } else {
        ++broker_;  // refused or unreachable: the next one
    }
    retry_timer_.expires_after(backoff_.next());
    retry_timer_.async_wait(
        [this, alive = std::weak_ptr<int>(alive_)](boost::system::error_code ec) {
            if (alive.expired() || ec) return;
            connect();
        });
    if (was_accepted && handlers_.disconnected) handlers_.disconnected();
}

void MqttClient::stop(const Message& last) {
    if (closing_ || mosq_ == nullptr) return;
    closing_ = true;
    retry_timer_.cancel();
    resolver_.cancel();
    misc_timer_.cancel();
    unwrap();  // from here on the socket is driven below, bounded in time
    if (connected_) {
        // A clean goodbye: the offline status, then DISCONNECT (no Will). libmosquitto closes
        // the socket once the DISCONNECT is written.
        mosquitto_publish(mosq_, nullptr, last.topic.c_str(), static_cast<int>(last.payload.size()),
                          last.payload.data(), last.qos, last.retain);
        mosquitto_disconnect(mosq_);
        const auto deadline = std::chrono::steady_clock::now() + stop_timeout;
        for (int fd = mosquitto_socket(mosq_); fd >= 0; fd = mosquitto_socket(mosq_)) {
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                deadline - std::chrono::steady_clock::now());
            if (left.count() <= 0) break;
            pollfd p{fd, static_cast<short>(POLLIN | (mosquitto_want_write(mosq_) ? POLLOUT : 0)),
                     0};
            if (::poll(&p, 1, static_cast<int>(left.count())) < 0) break;
            if ((p.revents & (POLLOUT | POLLERR | POLLHUP)) != 0)
                mosquitto_loop_write(mosq_, 1);
            else if ((p.revents & POLLIN) != 0)
                mosquitto_loop_read(mosq_, 1);
        }
    }
    connected_ = false;
    // Whatever is still open is closed now, without waiting for the broker.
    mosquitto_destroy(mosq_);
    mosq_ = nullptr;
}

void MqttClient::on_connect(mosquitto* m, void* p, int rc) {
    auto* self = static_cast<MqttClient*>(p);
    if (rc != 0) {
        spdlog::warn("MQTT connection refused: {}", mosquitto_connack_string(rc));
        mosquitto_disconnect(m);
        return;
    }
    self->accepted_ = true;
    self->will_sent_ = true;
    self->connected_ = true;
    ++self->connects_;
    for (const auto& s : self->subscriptions_)
        mosquitto_subscribe(m, nullptr, s.c_str(), 1);
    const auto& o = self->online_;
    if (!o.topic.empty())  // a connection with no status of its own (Sparkplug's session)
        mosquitto_publish(m, nullptr, o.topic.c_str(), static_cast<int>(o.payload.size()),
                          o.payload.data(), o.qos, o.retain);
    spdlog::info("MQTT connected");
    if (self->handlers_.connected) self->handlers_.connected(self->generation_);
}

void MqttClient::on_disconnect(mosquitto*, void* p, int rc) {
    auto* self = static_cast<MqttClient*>(p);
    self->connected_ = false;
    if (rc == 0 || self->closing_) return;
    // libmosquitto 2.0.11 has no text for MOSQ_ERR_KEEPALIVE.
    spdlog::warn("MQTT connection lost: {}",
                 rc == MOSQ_ERR_KEEPALIVE
                     ? "no answer from the broker within the keepalive (or no CONNACK)"
                     : mosquitto_strerror(rc));
}

void MqttClient::on_publish(mosquitto*, void* p, int) {
    auto* self = static_cast<MqttClient*>(p);
    if (self->queued_ > 0) --self->queued_;
}

void MqttClient::on_message(mosquitto*, void* p, const mosquitto_message* m) {
    auto* self = static_cast<MqttClient*>(p);
    ++self->received_;
    if (!self->handlers_.message || self->closing_) return;
    self->handlers_.message(m->topic,
                            std::string(static_cast<const char*>(m->payload),
                                        static_cast<std::size_t>(std::max(m->payloadlen, 0))),
                            m->retain);
}

bool MqttClient::publish(const Message& m) {
    if (mosq_ == nullptr || closing_ || (!connected_ && m.qos == 0) ||
        queued_ >= config_.queue_limit) {
        ++dropped_;
        return false;
    }
    ++queued_;
    const int rc =
        mosquitto_publish(mosq_, nullptr, m.topic.c_str(), static_cast<int>(m.payload.size()),
                          m.payload.data(), m.qos, m.retain);
    // QoS 1 while disconnected: libmosquitto keeps it and sends it after the reconnect.
    if (rc != MOSQ_ERR_SUCCESS && !(rc == MOSQ_ERR_NO_CONN && m.qos > 0)) {
        if (queued_ > 0) --queued_;
        ++dropped_;
        return false;
    }
    ++published_;
    // Written when the socket is writable (writable()).
    if (socket_ && !writing_ && mosquitto_want_write(mosq_)) wait_write();
    return true;
}

}  // namespace fins::bridge
