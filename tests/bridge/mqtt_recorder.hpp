// The one MQTT client of the bridge tests and benchmarks (libmosquitto): subscribes to its
// filters, records every message it receives and publishes commands. The constructor returns
// once the broker has acknowledged every subscription (SUBACK) or refused the connection
// (CONNACK), at most 10 s: a test never sleeps for a subscription to settle. Every wait is
// bounded.
#pragma once

#include <mosquitto.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace fins::test::bridge {

struct Received {
    std::string topic;
    std::string payload;
    bool retain = false;
    std::chrono::steady_clock::time_point at;
    int mid = 0;  // the broker's message id (QoS 1): a redelivery repeats it
    [[nodiscard]] nlohmann::json json() const {
        return nlohmann::json::parse(payload, nullptr, false);
    }
};

class Recorder {
  public:
    struct Options {
        std::string ca_file;  // TLS with this CA (empty: plain TCP)
        std::string username;
        std::string password;
        // A persistent session (clean_session = false) under this client id: what is
        // published to its filters while it reconnects is queued by the broker for it.
        std::string persistent_id;
    };
    Recorder(std::uint16_t port, std::vector<std::string> filters, const Options& o = {})
        : filters_(std::move(filters)) {
        static std::once_flag once;
        std::call_once(once, [] { mosquitto_lib_init(); });
        static std::atomic<int> n{0};
        const auto id = o.persistent_id.empty()
                            ? "recorder-" + std::to_string(::getpid()) + "-" + std::to_string(n++)
                            : o.persistent_id;
        m_ = mosquitto_new(id.c_str(), o.persistent_id.empty(), this);
        // Subscribes on every (re)connection, so a broker restart loses no filter.
        mosquitto_connect_callback_set(m_, [](mosquitto* m, void* self, int rc) {
            auto* r = static_cast<Recorder*>(self);
            {
                std::lock_guard lock(r->mu_);
                r->connack_ = rc;
                r->cv_.notify_all();
            }
            if (rc != 0) return;
            for (const auto& f : r->filters_)
                mosquitto_subscribe(m, nullptr, f.c_str(), 1);
        });
        mosquitto_subscribe_callback_set(m_, [](mosquitto*, void* self, int, int, const int*) {
            auto* r = static_cast<Recorder*>(self);
            std::lock_guard lock(r->mu_);
            ++r->subacks_;
            r->cv_.notify_all();
        });
        mosquitto_message_callback_set(
            m_, [](mosquitto*, void* self, const mosquitto_message* msg) {
                auto* r = static_cast<Recorder*>(self);
                Received rec{msg->topic,
                             std::string(static_cast<const char*>(msg->payload),
                                         static_cast<std::size_t>(msg->payloadlen)),
                             msg->retain, std::chrono::steady_clock::now(), msg->mid};
                std::lock_guard lock(r->mu_);
                r->messages_.push_back(std::move(rec));
                r->cv_.notify_all();
            });
        if (!o.ca_file.empty())
            mosquitto_tls_set(m_, o.ca_file.c_str(), nullptr, nullptr, nullptr, nullptr);
        if (!o.username.empty())
            mosquitto_username_pw_set(m_, o.username.c_str(), o.password.c_str());
        if (mosquitto_connect(m_, "127.0.0.1", port, 30) != MOSQ_ERR_SUCCESS) return;
        mosquitto_loop_start(m_);
        std::unique_lock lock(mu_);
        cv_.wait_for(lock, std::chrono::seconds(10), [&] {
            return connack_ > 0 || (connack_ == 0 && subacks_ >= filters_.size());
        });
        connected_ = connack_ == 0 && subacks_ >= filters_.size();
    }
    // One filter (a literal: a braced list goes to the constructor above).
    Recorder(std::uint16_t port, const char* filter, const Options& o = {})
        : Recorder(port, std::vector<std::string>{filter}, o) {}
    ~Recorder() {
        mosquitto_disconnect(m_);
        mosquitto_loop_stop(m_, false);
        mosquitto_destroy(m_);
    }
    Recorder(const Recorder&) = delete;
    Recorder& operator=(const Recorder&) = delete;

    // Connected, and every filter acknowledged, when the constructor returned.
    [[nodiscard]] bool connected() const { return connected_; }

    void publish(const std::string& topic, const std::string& payload, int qos = 1,
                 bool retain = false) {
        mosquitto_publish(m_, nullptr, topic.c_str(), static_cast<int>(payload.size()),
                          payload.data(), qos, retain);
    }

    // Waits until pred(messages) holds (at most timeout); the last answer of pred. pred runs
    // with the recorder locked: it must use its argument, not messages() or count().
    bool wait(const std::function<bool(const std::vector<Received>&)>& pred,
              std::chrono::milliseconds timeout) {
        std::unique_lock lock(mu_);
        return cv_.wait_for(lock, timeout, [&] { return pred(messages_); });
    }
    // The first message from index `from` on that satisfies `pred`, waiting at most `timeout`.
    std::optional<Received> wait_for(const std::function<bool(const Received&)>& pred,
                                     std::chrono::milliseconds timeout = std::chrono::seconds(15),
                                     std::size_t from = 0) {
        std::optional<Received> found;
        wait(
            [&](const std::vector<Received>& ms) {
                for (std::size_t i = from; i < ms.size(); ++i)
                    if (pred(ms[i])) {
                        found = ms[i];
                        return true;
                    }
                return false;
            },
            timeout);
        return found;
    }
    // The first message on `topic` whose JSON payload satisfies `pred` (as wait_for).
    std::optional<Received> wait_topic(const std::string& topic,
                                       const std::function<bool(const nlohmann::json&)>& pred,
                                       std::chrono::milliseconds timeout = std::chrono::seconds(15),
                                       std::size_t from = 0) {
        return wait_for([&](const Received& r) { return r.topic == topic && pred(r.json()); },
                        timeout, from);
    }
    std::vector<Received> messages() const {
        std::lock_guard lock(mu_);
        return messages_;
    }
    std::size_t count() const {
        std::lock_guard lock(mu_);
        return messages_.size();
    }

  private:
    mosquitto* m_ = nullptr;
    std::vector<std::string> filters_;
    mutable std::mutex mu_;
    std::condition_variable cv_;
    int connack_ = -1;  // -1: no CONNACK yet
    std::size_t subacks_ = 0;
    bool connected_ = false;
    std::vector<Received> messages_;
};

}  // namespace fins::test::bridge
