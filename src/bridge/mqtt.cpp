#include "bridge/mqtt.hpp"

#include <mosquitto.h>

#include <algorithm>
#include <random>

#include <spdlog/spdlog.h>

#include "bridge/poll_schedule.hpp"

namespace fins::bridge {

namespace {

void init_library() {
    static const int once = mosquitto_lib_init();
    (void)once;
}

}  // namespace

MqttClient::MqttClient(const Mqtt& config, Message will, Message online,
                       std::vector<std::string> subscriptions, Handlers handlers, bool persistent)
    : config_(config),
      will_(std::move(will)),
      online_(std::move(online)),
      subscriptions_(std::move(subscriptions)),
      handlers_(std::move(handlers)),
      persistent_(persistent) {}

MqttClient::~MqttClient() {
    if (thread_.joinable()) stop(will_);
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
    thread_ = std::thread([this] { loop(); });
    return true;
}

void MqttClient::stop(const Message& last) {
    {
        std::lock_guard lock(mutex_);
        if (closing_) return;
        closing_ = true;
        last_ = last;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

bool MqttClient::wait(std::chrono::milliseconds d) {
    std::unique_lock lock(mutex_);
    return !wake_.wait_for(lock, d, [this] { return closing_; });
}

void MqttClient::loop() {
    Backoff backoff(config_.backoff_min, config_.backoff_max,
                    (std::uint64_t{std::random_device{}()} << 32) | std::random_device{}());
    std::size_t broker = 0;
    const auto closing = [this] {
        std::lock_guard lock(mutex_);
        return closing_;
    };
    // A new Will (Sparkplug: the next bdSeq) only once the last one went out in a CONNECT:
    // an attempt that reached no broker sent none.
    bool will_sent = true;
    while (!closing()) {
        const Broker& b = config_.brokers[broker % config_.brokers.size()];
        accepted_ = false;
        if (handlers_.will && will_sent) {
            will_ = handlers_.will();
            mosquitto_will_set(mosq_, will_.topic.c_str(), static_cast<int>(will_.payload.size()),
                               will_.payload.data(), will_.qos, will_.retain);
            will_sent = false;
        }
        int rc = mosquitto_connect(mosq_, b.host.c_str(), b.port,
                                   static_cast<int>(config_.keepalive.count()));
        if (rc == MOSQ_ERR_SUCCESS) {
            will_sent = true;  // connected: the CONNECT with this Will is on its way
            while (rc == MOSQ_ERR_SUCCESS && !closing())
                rc = mosquitto_loop(mosq_, 100, 1);
            if (closing() && connected_) {
                // A clean goodbye: the offline status, then DISCONNECT (no Will).
                Message last;
                {
                    std::lock_guard lock(mutex_);
                    last = last_;
                }
                mosquitto_publish(mosq_, nullptr, last.topic.c_str(),
                                  static_cast<int>(last.payload.size()), last.payload.data(),
                                  last.qos, last.retain);
                mosquitto_disconnect(mosq_);
                for (int i = 0; i < 20 && mosquitto_loop(mosq_, 100, 1) == MOSQ_ERR_SUCCESS; ++i) {
                }
                connected_ = false;
                return;
            }
        } else {
            spdlog::warn("MQTT broker {}:{}: {}", b.host, b.port, mosquitto_strerror(rc));
        }
        connected_ = false;
        queued_ = 0;  // what libmosquitto held for the lost connection is gone
        if (accepted_ && handlers_.disconnected) handlers_.disconnected();
        if (closing()) return;
        if (accepted_) {
            backoff.reset();  // a lost session: the same broker first
        } else {
            ++broker;  // refused or unreachable: the next one
        }
        if (!wait(backoff.next())) return;
    }
}

void MqttClient::on_connect(mosquitto* m, void* p, int rc) {
    auto* self = static_cast<MqttClient*>(p);
    if (rc != 0) {
        spdlog::warn("MQTT connection refused: {}", mosquitto_connack_string(rc));
        mosquitto_disconnect(m);
        return;
    }
    self->accepted_ = true;
    self->connected_ = true;
    ++self->connects_;
    for (const auto& s : self->subscriptions_)
        mosquitto_subscribe(m, nullptr, s.c_str(), 1);
    const auto& o = self->online_;
    if (!o.topic.empty())  // a connection with no status of its own (Sparkplug's session)
        mosquitto_publish(m, nullptr, o.topic.c_str(), static_cast<int>(o.payload.size()),
                          o.payload.data(), o.qos, o.retain);
    spdlog::info("MQTT connected");
    if (self->handlers_.connected) self->handlers_.connected();
}

void MqttClient::on_disconnect(mosquitto*, void* p, int rc) {
    auto* self = static_cast<MqttClient*>(p);
    self->connected_ = false;
    if (rc != 0) spdlog::warn("MQTT connection lost: {}", mosquitto_strerror(rc));
}

void MqttClient::on_publish(mosquitto*, void* p, int) {
    auto* self = static_cast<MqttClient*>(p);
    std::size_t q = self->queued_.load();
    while (q > 0 && !self->queued_.compare_exchange_weak(q, q - 1)) {
    }
}

void MqttClient::on_message(mosquitto*, void* p, const mosquitto_message* m) {
    auto* self = static_cast<MqttClient*>(p);
    ++self->received_;
    if (!self->handlers_.message) return;
    self->handlers_.message(m->topic,
                            std::string(static_cast<const char*>(m->payload),
                                        static_cast<std::size_t>(std::max(m->payloadlen, 0))),
                            m->retain);
}

bool MqttClient::publish(const Message& m) {
    if (!connected_ && m.qos == 0) {
        ++dropped_;
        return false;
    }
    if (queued_.fetch_add(1) >= config_.queue_limit) {
        queued_.fetch_sub(1);
        ++dropped_;
        return false;
    }
    const int rc =
        mosquitto_publish(mosq_, nullptr, m.topic.c_str(), static_cast<int>(m.payload.size()),
                          m.payload.data(), m.qos, m.retain);
    // QoS 1 while disconnected: libmosquitto keeps it and sends it after the reconnect.
    if (rc != MOSQ_ERR_SUCCESS && !(rc == MOSQ_ERR_NO_CONN && m.qos > 0)) {
        queued_.fetch_sub(1);
        ++dropped_;
        return false;
    }
    ++published_;
    return true;
}

MqttStats MqttClient::stats() const {
    return {published_.load(), dropped_.load(), connects_.load(), received_.load()};
}

}  // namespace fins::bridge
