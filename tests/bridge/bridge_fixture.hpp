// Real parts for the bridge tests: a mosquitto broker (bridge_processes.hpp's) plain, with
// TLS from a CA made by openssl, or with a password file from mosquitto_passwd,
// a libmosquitto subscriber that records every message, and fins-bridge itself. Every
// wait is bounded.
#pragma once

#include <arpa/inet.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bridge/bridge_processes.hpp"
#include "integration/finsd_run.hpp"

namespace fins::bridge::test {

using fins::test::Child;
using fins::test::ScratchDir;

using fins::test::bridge::bridge_path;
using fins::test::bridge::Mosquitto;
using fins::test::bridge::Proc;
inline std::uint16_t free_port() {
    return fins::test::bridge::free_tcp_port();
}
inline bool accepts(std::uint16_t port) {
    return fins::test::bridge::tcp_connectable(port);
}

inline int shell(const std::string& command) {
    return std::system(("(" + command + ") >/dev/null 2>&1").c_str());
}

// TLS material made by openssl in `dir`: ca.crt, server.crt/key for 127.0.0.1.
inline bool make_tls(const ScratchDir& dir) {
    const std::string d = dir.path().string();
    return shell("cd " + d +
                 " && openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=finskit-test-ca"
                 " -keyout ca.key -out ca.crt"
                 " && openssl req -newkey rsa:2048 -nodes -subj /CN=127.0.0.1"
                 " -keyout server.key -out server.csr"
                 " && printf 'subjectAltName=IP:127.0.0.1' > san.ext"
                 " && openssl x509 -req -in server.csr -CA ca.crt -CAkey ca.key -CAcreateserial"
                 " -days 1 -extfile san.ext -out server.crt"
                 // mosquitto started as root reads them as the user "mosquitto"
                 " && chmod 0755 . && chmod 0644 ca.crt server.crt server.key") == 0;
}

struct Received {
    std::string topic;
    std::string payload;
    bool retain = false;
    [[nodiscard]] nlohmann::json json() const {
        return nlohmann::json::parse(payload, nullptr, false);
    }
};

// Subscribes to `filter` and records every message; publish() sends commands.
class Subscriber {
  public:
    struct Options {
        std::string ca_file;
        std::string username;
        std::string password;
    };
    Subscriber(std::uint16_t port, const std::string& filter, const Options& o = {}) {
        mosquitto_lib_init();
        m_ = mosquitto_new(nullptr, true, this);
        mosquitto_message_callback_set(
            m_, [](mosquitto*, void* self, const mosquitto_message* msg) {
                auto* s = static_cast<Subscriber*>(self);
                std::lock_guard lock(s->mutex_);
                s->messages_.push_back({msg->topic,
                                        std::string(static_cast<const char*>(msg->payload),
                                                    static_cast<std::size_t>(msg->payloadlen)),
                                        msg->retain});
                s->cv_.notify_all();
            });
        mosquitto_connect_callback_set(m_, [](mosquitto*, void* self, int rc) {
            auto* s = static_cast<Subscriber*>(self);
            std::lock_guard lock(s->mutex_);
            s->connack_ = rc;
            s->cv_.notify_all();
        });
        if (!o.ca_file.empty())
            mosquitto_tls_set(m_, o.ca_file.c_str(), nullptr, nullptr, nullptr, nullptr);
        if (!o.username.empty())
            mosquitto_username_pw_set(m_, o.username.c_str(), o.password.c_str());
        if (mosquitto_connect(m_, "127.0.0.1", port, 30) != MOSQ_ERR_SUCCESS) return;
        mosquitto_loop_start(m_);
        std::unique_lock lock(mutex_);
        cv_.wait_for(lock, std::chrono::seconds(10), [this] { return connack_ >= 0; });
        if (connack_ != 0) return;
        lock.unlock();
        int mid = 0;
        mosquitto_subscribe(m_, &mid, filter.c_str(), 1);
        connected_ = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));  // SUBACK on its way
    }
    ~Subscriber() {
        mosquitto_disconnect(m_);
        mosquitto_loop_stop(m_, false);
        mosquitto_destroy(m_);
    }
    [[nodiscard]] bool connected() const { return connected_; }

    void publish(const std::string& topic, const std::string& payload, bool retain = false) {
        mosquitto_publish(m_, nullptr, topic.c_str(), static_cast<int>(payload.size()),
                          payload.data(), 1, retain);
    }

    // The first message from index `from` on that satisfies `pred`, waiting at most `timeout`.
    std::optional<Received> wait_for(const std::function<bool(const Received&)>& pred,
                                     std::chrono::milliseconds timeout = std::chrono::seconds(15),
                                     std::size_t from = 0) {
        std::unique_lock lock(mutex_);
        std::optional<Received> found;
        cv_.wait_for(lock, timeout, [&] {
            for (std::size_t i = from; i < messages_.size(); ++i)
                if (pred(messages_[i])) {
                    found = messages_[i];
                    return true;
                }
            return false;
        });
        return found;
    }
    std::optional<Received> wait_topic(const std::string& topic,
                                       const std::function<bool(const nlohmann::json&)>& pred,
                                       std::chrono::milliseconds timeout = std::chrono::seconds(15),
                                       std::size_t from = 0) {
        return wait_for([&](const Received& r) { return r.topic == topic && pred(r.json()); },
                        timeout, from);
    }
    std::size_t count() {
        std::lock_guard lock(mutex_);
        return messages_.size();
    }
    std::vector<Received> messages() {
        std::lock_guard lock(mutex_);
        return messages_;
    }

  private:
    mosquitto* m_ = nullptr;
    std::mutex mutex_;
    std::condition_variable cv_;
    std::vector<Received> messages_;
    int connack_ = -1;
    bool connected_ = false;
};

// fins-bridge with `config` (TOML text) written to `dir`.
class BridgeProcess {
  public:
    BridgeProcess(const ScratchDir& dir, const std::string& config,
                  std::vector<std::string> extra = {}) {
        static int n = 0;
        const auto file = dir.write("bridge-" + std::to_string(n++) + ".toml", config);
        std::vector<std::string> argv{bridge_path, "--config",   file,  "--log-level",
                                      "warn",      "--instance", "test"};
        argv.insert(argv.end(), extra.begin(), extra.end());
        child_ = std::make_unique<Proc>(argv, file + ".log");
    }
    // Stops it (SIGKILL after 20 s); its exit status and what it logged.
    struct Stopped {
        int exit_code = -1;  // 128 + signal when killed by one
        std::string err;
    };
    Stopped stop(int signal = SIGTERM) {
        const int status = child_->kill(signal, std::chrono::seconds(20));
        return {status, child_->log()};
    }
    Proc& child() { return *child_; }

  private:
    std::unique_ptr<Proc> child_;
};

inline std::string mqtt_section(std::uint16_t port, const std::string& extra = "") {
    return "[mqtt]\nhost = \"127.0.0.1\"\nport = " + std::to_string(port) +
           "\ntopic_prefix = \"t\"\nbackoff_min_ms = 50\nbackoff_max_ms = 500\n" + extra;
}

}  // namespace fins::bridge::test
