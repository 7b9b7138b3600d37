// The MQTT side: Debian's libmosquitto (C, thread-safe, TLS, MQTT 3.1.1/5, the client of
// the broker the tests run) rather than Paho (not in Debian for C++ at the version we
// need, and two libraries, C and C++, for what libmosquitto does in one).
//
// The client runs on its own thread (mosquitto_loop), not inside the poller's
// io_context: the poller thread then spends nothing on MQTT framing, TLS or broker
// stalls, and a broker that stops reading cannot delay a poll. The hand-offs are bounded:
// - outgoing: publish() is called from the poller thread and hands the message to
//   libmosquitto; at most Mqtt::queue_limit messages may wait to be written. Beyond that
//   (or while disconnected) data messages (QoS 0) are dropped and counted in
//   stats().dropped; statuses are published again after every connect, so nothing
//   retained is lost for good.
// - incoming: commands are passed to the handler, which posts them to the io_context
//   with its own bound (bridge.hpp).
// Connection: the brokers are tried in turn; after a failure or a lost connection the
// next attempt waits uniform(0, min(backoff_max, backoff_min x 2^n)) (full jitter, n
// reset by an accepted connection). The Will is the bridge's offline status.
// Session: a persistent client (clean_session = false, `persistent`) keeps its
// subscriptions on the broker while it is away, and the broker queues the QoS 1 messages
// published to them meanwhile and delivers them on the next CONNECT with the same client id
// (MQTT 3.1.1 3.1.2.4): the bridge's write commands (docs/bridge.md "Writes").
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "bridge/config.hpp"
#include "bridge/payload.hpp"

struct mosquitto;
struct mosquitto_message;

namespace fins::bridge {

struct MqttStats {
    std::uint64_t published = 0;
    std::uint64_t dropped = 0;   // at the queue bound or while disconnected
    std::uint64_t connects = 0;  // accepted connections
    std::uint64_t received = 0;
};

class MqttClient {
  public:
    struct Handlers {
        std::function<void()> connected;  // on the MQTT thread, after subscribing
        std::function<void(std::string topic, std::string payload, bool retained)> message;
        // On the MQTT thread when an accepted connection is lost (not after stop()).
        std::function<void()> disconnected;
        // When set, the Will for each CONNECT, asked for before the first attempt and again
        // after every attempt that sent a CONNECT (Sparkplug's NDEATH carries a bdSeq that
        // changes per CONNECT, not per unreachable broker); the constructor's `will` is then
        // only the default.
        std::function<Message()> will;
    };
    MqttClient(const Mqtt& config, Message will, Message online,
               std::vector<std::string> subscriptions, Handlers handlers, bool persistent = false);
    ~MqttClient();
    MqttClient(const MqttClient&) = delete;
    MqttClient& operator=(const MqttClient&) = delete;

    // Starts the thread; false (with the reason) when libmosquitto refuses the settings
    // (a TLS file that cannot be read ...).
    bool start(std::string& error);
    // Publishes `last` (the bridge's offline status), disconnects cleanly (no Will) and
    // joins the thread; at most ~2 s.
    void stop(const Message& last);

    // Thread-safe. False when the message was dropped (see above). A QoS 1 message handed
    // over while disconnected stays in libmosquitto's queue and is sent after the reconnect.
    bool publish(const Message& m);
    [[nodiscard]] bool connected() const noexcept { return connected_; }
    [[nodiscard]] MqttStats stats() const;

  private:
    static void on_connect(mosquitto*, void* self, int rc);
    static void on_disconnect(mosquitto*, void* self, int rc);
    static void on_publish(mosquitto*, void* self, int mid);
    static void on_message(mosquitto*, void* self, const ::mosquitto_message* m);
    void loop();
    bool wait(std::chrono::milliseconds d);

    Mqtt config_;
    Message will_;
    Message online_;
    std::vector<std::string> subscriptions_;
    Handlers handlers_;
    bool persistent_ = false;
    mosquitto* mosq_ = nullptr;
    std::thread thread_;
    std::mutex mutex_;
    std::condition_variable wake_;
    bool closing_ = false;  // guarded by mutex_
    Message last_;          // guarded by mutex_
    std::atomic<bool> connected_{false};
    std::atomic<bool> accepted_{false};
    std::atomic<std::size_t> queued_{0};
    std::atomic<std::uint64_t> published_{0};
    std::atomic<std::uint64_t> dropped_{0};
    std::atomic<std::uint64_t> connects_{0};
    std::atomic<std::uint64_t> received_{0};
};

}  // namespace fins::bridge
