// The MQTT side: Debian's libmosquitto (C, TLS, MQTT 3.1.1/5, the client of the broker the
// tests run) rather than Paho (not in Debian for C++ at the version we need, and two
// libraries, C and C++, for what libmosquitto does in one).
//
// The client runs on the bridge's io_context, like the pollers: no MQTT thread. libmosquitto's
// socket (mosquitto_socket()) is watched by an asio::posix::stream_descriptor that never owns
// it (released, never closed by Asio, wrapped again after every reconnect since the socket
// changes): readable -> mosquitto_loop_read, writable while mosquitto_want_write() ->
// mosquitto_loop_write, a one-second timer -> mosquitto_loop_misc (keepalive, and the end of
// an attempt whose CONNACK does not come within the keepalive). TLS runs through the same
// calls: its handshake is driven by loop_read on either readiness. Every callback
// (connected, message, disconnected, will) therefore runs on the io_context's thread, and
// nothing here is shared with another thread.
// - outgoing: publish() hands the message to libmosquitto's queue, written when the socket
//   is writable (everything queued at once, corked into full segments); at most
//   Mqtt::queue_limit messages may wait to be written. Beyond that
//   (or while disconnected) data messages (QoS 0) are dropped and counted in
//   stats().dropped; statuses are published again after every connect, so nothing retained
//   is lost for good.
// - incoming: commands are passed to the handler as they are read.
// Connection: the brokers are tried in turn (mosquitto_connect_async: the TCP connect does
// not block). A broker given by name is resolved first on Asio's resolver (getaddrinfo off
// this thread, as fins::Client resolves a PLC): a name that does not resolve, or a DNS
// server that does not answer, is a failed attempt that never holds up the pollers.
// Without TLS libmosquitto then gets the addresses one at a time (the next when an attempt
// fails before CONNACK, as libmosquitto itself would try them), so it looks up nothing.
// With TLS it gets
// the name, which its certificate check and SNI need, and looks it up once more itself
// (blocking, but just after the same lookup succeeded). After a failure or a lost connection the
// next attempt waits uniform(0, min(backoff_max, backoff_min x 2^n)) (full jitter, n reset by an
// accepted connection). The Will is the bridge's offline status. Every CONNECT attempt has a
// generation number; the connected handler gets the generation of the connection it belongs to.
// Session: a persistent client (clean_session = false, `persistent`) keeps its
// subscriptions on the broker while it is away, and the broker queues the QoS 1 messages
// published to them meanwhile and delivers them on the next CONNECT with the same client id
// (MQTT 3.1.1 3.1.2.4): the bridge's write commands (docs/bridge.md "Writes").
// Shutdown: stop() publishes the last message, sends DISCONNECT and closes the socket within
// stop_timeout whatever the broker does (a broker that never reads or never answers).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/steady_timer.hpp>

#include "bridge/config.hpp"
#include "bridge/payload.hpp"
#include "bridge/poll/poll_schedule.hpp"

struct mosquitto;
struct mosquitto_message;

namespace fins::bridge {

namespace asio = boost::asio;

struct MqttStats {
    std::uint64_t published = 0;
    std::uint64_t dropped = 0;   // at the queue bound or while disconnected
    std::uint64_t connects = 0;  // accepted connections
    std::uint64_t received = 0;
};

class MqttClient {
  public:
    // How long stop() may take to say goodbye before it closes the socket anyway.
    static constexpr std::chrono::milliseconds stop_timeout{2000};

    struct Handlers {
        // After CONNACK and the subscriptions, with the generation of this connection.
        std::function<void(std::uint64_t generation)> connected;
        std::function<void(std::string topic, std::string payload, bool retained)> message;
        // When an accepted connection is lost (not after stop()).
        std::function<void()> disconnected;
        // When set, the Will for each CONNECT, asked for before the first attempt and again
        // after every attempt that sent a CONNECT (Sparkplug's NDEATH carries a bdSeq that
        // changes per CONNECT, not per unreachable broker); the constructor's `will` is then
        // only the default.
        std::function<Message()> will;
    };
    MqttClient(asio::io_context& io, const Mqtt& config, Message will, Message online,
               std::vector<std::string> subscriptions, Handlers handlers, bool persistent = false);
    ~MqttClient();
    MqttClient(const MqttClient&) = delete;
    MqttClient& operator=(const MqttClient&) = delete;

    // Makes the first attempt; false (with the reason) when libmosquitto refuses the
    // settings (a TLS file that cannot be read ...).
    bool start(std::string& error);
    // Publishes `last` (the bridge's offline status) and disconnects cleanly (no Will) when
    // connected; closes the socket in any case, within stop_timeout. Blocks the calling
    // thread (the io_context's) for that long at most.
    void stop(const Message& last);

    // False when the message was dropped (see above). A QoS 1 message handed over while
    // disconnected stays in libmosquitto's queue and is sent after the reconnect.
    bool publish(const Message& m);
    [[nodiscard]] bool connected() const noexcept { return connected_; }
    // The CONNECT attempt the client is on (1 for the first).
    [[nodiscard]] std::uint64_t generation() const noexcept { return generation_; }
    // A lookup of the broker's name is under way on Asio's resolver thread (which the
    // io_context's destructor joins: getaddrinfo cannot be interrupted).
    [[nodiscard]] bool looking_up() const noexcept { return looking_up_; }
    [[nodiscard]] MqttStats stats() const noexcept {
        return {published_, dropped_, connects_, received_};
    }

  private:
    static void on_connect(mosquitto*, void* self, int rc);
    static void on_disconnect(mosquitto*, void* self, int rc);
    static void on_publish(mosquitto*, void* self, int mid);
    static void on_message(mosquitto*, void* self, const ::mosquitto_message* m);
    // The next attempt: resolves the broker's name (connect_to() follows).
    void connect();
    // mosquitto_connect_async to `host` (the broker's address, or its name with TLS).
    void connect_to(const std::string& host, std::uint16_t port);
    // connect_to() the next of untried_ (not empty).
    void next_address(std::uint16_t port);
    // After every libmosquitto call: follows its socket (wrapped again when it changed, a
    // lost connection when it is gone) and waits for what it needs.
    void sync();
    void wait_read();
    void wait_write();
    void misc();
    void readable();
    void writable();
    void lost();
    void unwrap() noexcept;

    asio::io_context& io_;
    Mqtt config_;
    Message will_;
    Message online_;
    std::vector<std::string> subscriptions_;
    Handlers handlers_;
    bool persistent_ = false;
    mosquitto* mosq_ = nullptr;
    std::optional<asio::posix::stream_descriptor> socket_;  // never owns the fd
    int fd_ = -1;
    bool reading_ = false;
    bool writing_ = false;
    bool misc_armed_ = false;
    std::uint64_t wraps_ = 0;  // socket_ wrapped again: waits of an earlier one are stale
    bool retrying_ = false;    // between a failed/lost connection and the next attempt
    asio::steady_timer misc_timer_;
    asio::steady_timer retry_timer_;
    asio::ip::tcp::resolver resolver_;
    std::uint64_t resolving_ = 0;  // the attempt a resolution belongs to (0: none)
    bool looking_up_ = false;
    // The current broker's addresses (or its name, with TLS) not tried yet in this attempt.
    std::vector<std::string> untried_;
    Backoff backoff_;
    std::shared_ptr<int> alive_ = std::make_shared<int>(0);  // for handlers that outlive this
    std::size_t broker_ = 0;
    std::uint64_t generation_ = 0;
    // A new Will (Sparkplug: the next bdSeq) only once the last one went out in a CONNECT
    // (written, or answered by CONNACK): an attempt that reached no broker sent none.
    bool will_sent_ = true;
    bool accepted_ = false;  // the current attempt got a CONNACK
    bool connected_ = false;
    bool closing_ = false;
    std::size_t queued_ = 0;
    std::uint64_t published_ = 0;
    std::uint64_t dropped_ = 0;
    std::uint64_t connects_ = 0;
    std::uint64_t received_ = 0;
};

}  // namespace fins::bridge
