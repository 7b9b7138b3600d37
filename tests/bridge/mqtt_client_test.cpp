// The MQTT client on the bridge's io_context (mqtt.hpp): stop() ends within its bound whatever
// the broker does. Issue 27: fins-bridge's MQTT thread connected with a blocking connect, so a
// broker whose listen queue is full (SYNs dropped: a host that does not answer) held SIGTERM
// for the two minutes of the kernel's SYN retries. The silent brokers here are listeners on
// loopback that never read; every wait is bounded.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <future>
#include <memory>
#include <thread>

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "bridge/bridge_fixture.hpp"
#include "bridge/mqtt.hpp"

namespace fins::bridge {
namespace {

using namespace std::chrono_literals;

int tcp_socket() {
    return ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
}

sockaddr_in loopback(std::uint16_t port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(port);
    return a;
}

// A listener on 127.0.0.1 that never reads. With room in its queue the kernel completes every
// TCP handshake (a broker that accepts and never answers); `full`: its queue (backlog 0) is
// taken by a connection of its own, so the SYNs of others are dropped (a broker that never
// answers at all).
class SilentBroker {
  public:
    explicit SilentBroker(bool full) {
        fd_ = tcp_socket();
        auto a = loopback(0);
        socklen_t len = sizeof a;
        if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
            ::listen(fd_, full ? 0 : 16) != 0 ||
            ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
            return;
        port_ = ntohs(a.sin_port);
        if (full) {
            filler_ = tcp_socket();
            const auto to = loopback(port_);
            if (::connect(filler_, reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0)
                port_ = 0;
        }
    }
    ~SilentBroker() {
        for (const int fd : {filler_, fd_})
            if (fd >= 0) ::close(fd);
    }
    SilentBroker(const SilentBroker&) = delete;
    SilentBroker& operator=(const SilentBroker&) = delete;
    [[nodiscard]] std::uint16_t port() const { return port_; }

  private:
    int fd_ = -1;
    int filler_ = -1;
    std::uint16_t port_ = 0;
};

// A broker that answers the first CONNECT with CONNACK and then never reads again: what the
// client writes after that stays in the socket buffers until they are full.
class DeafBroker {
  public:
    DeafBroker() {
        fd_ = tcp_socket();
        auto a = loopback(0);
        socklen_t len = sizeof a;
        const int small = 4096;  // inherited by the accepted socket: fills sooner
        ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
        if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
            ::listen(fd_, 4) != 0 || ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
            return;
        port_ = ntohs(a.sin_port);
        thread_ = std::thread([this] {
            const timeval limit{10, 0};
            ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
            client_ = ::accept(fd_, nullptr, nullptr);
            if (client_ < 0) return;
            ::setsockopt(client_, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
            char buf[256];
            if (::recv(client_, buf, sizeof buf, 0) <= 0) return;  // the CONNECT
            const unsigned char connack[] = {0x20, 0x02, 0x00, 0x00};
            (void)::send(client_, connack, sizeof connack, MSG_NOSIGNAL);
        });
    }
    ~DeafBroker() {
        if (thread_.joinable()) thread_.join();
        for (const int fd : {client_, fd_})
            if (fd >= 0) ::close(fd);
    }
    DeafBroker(const DeafBroker&) = delete;
    DeafBroker& operator=(const DeafBroker&) = delete;
    [[nodiscard]] std::uint16_t port() const { return port_; }

  private:
    int fd_ = -1;
    int client_ = -1;
    std::uint16_t port_ = 0;
    std::thread thread_;
};

Mqtt settings(std::uint16_t port) {
    Mqtt m;
    m.brokers.push_back({"127.0.0.1", port});
    m.client_id = "finskit-mqtt-client-test";
    m.keepalive = 30s;  // longer than any wait here: the CONNACK timeout plays no part
    m.backoff_min = 50ms;
    m.backoff_max = 200ms;
    return m;
}

// The client and its io_context; left behind (never freed) when stop() does not return, so
// that the thread still in it touches nothing freed.
struct Rig {
    asio::io_context io{1};
    std::unique_ptr<MqttClient> client;
    explicit Rig(const Mqtt& m) {
        client = std::make_unique<MqttClient>(
            io, m, Message{"t/status", "offline", 1, true}, Message{"t/status", "online", 1, true},
            std::vector<std::string>{"t/cmd"}, MqttClient::Handlers{});
    }
    // Runs the io_context until `done` or `limit`.
    bool run_until(const std::function<bool()>& done, std::chrono::milliseconds limit) {
        const auto deadline = std::chrono::steady_clock::now() + limit;
        while (!done() && std::chrono::steady_clock::now() < deadline) {
            io.restart();
            io.run_for(10ms);
        }
        return done();
    }
};

// Calls stop() on a thread of its own: true when it returned within `limit`.
bool stops_within(std::unique_ptr<Rig>& rig, std::chrono::seconds limit) {
    auto done = std::make_shared<std::promise<void>>();
    auto returned = done->get_future();
    Rig* r = rig.get();
    std::thread t([r, done] {
        r->client->stop(Message{"t/status", "offline", 1, true});
        done->set_value();
    });
    if (returned.wait_for(limit) == std::future_status::ready) {
        t.join();
        return true;
    }
    t.detach();
    (void)rig.release();
    return false;
}

TEST(MqttClient, StopReturnsWhenTheBrokerNeverAnswersTheTcpConnect) {
    SilentBroker broker(true);
    ASSERT_NE(broker.port(), 0);
    auto rig = std::make_unique<Rig>(settings(broker.port()));
    std::string error;
    ASSERT_TRUE(rig->client->start(error)) << error;
    // The attempt is under way (its SYNs dropped) and the io_context goes on meanwhile.
    EXPECT_FALSE(rig->run_until([] { return false; }, 300ms));
    EXPECT_FALSE(rig->client->connected());
    EXPECT_TRUE(stops_within(rig, 10s));
}

TEST(MqttClient, StopReturnsWhenTheBrokerAcceptsAndNeverAnswers) {
    SilentBroker broker(false);
    ASSERT_NE(broker.port(), 0);
    auto rig = std::make_unique<Rig>(settings(broker.port()));
    std::string error;
    ASSERT_TRUE(rig->client->start(error)) << error;
    EXPECT_FALSE(rig->run_until([] { return false; }, 300ms));
    EXPECT_FALSE(rig->client->connected());
    EXPECT_EQ(rig->client->stats().connects, 0u);
    EXPECT_TRUE(stops_within(rig, 10s));
}

TEST(MqttClient, StopReturnsWhenATlsBrokerNeverAnswersTheHandshake) {
    test::ScratchDir dir("mqtt-silent-tls");
    if (!test::make_tls(dir)) GTEST_SKIP() << "openssl could not make the TLS files";
    SilentBroker broker(false);
    ASSERT_NE(broker.port(), 0);
    auto m = settings(broker.port());
    m.ca_file = (dir.path() / "ca.crt").string();
    auto rig = std::make_unique<Rig>(m);
    std::string error;
    ASSERT_TRUE(rig->client->start(error)) << error;
    EXPECT_FALSE(rig->run_until([] { return false; }, 300ms));
    EXPECT_FALSE(rig->client->connected());
    EXPECT_TRUE(stops_within(rig, 10s));
}

TEST(MqttClient, TheGoodbyeIsBoundedWhenTheBrokerStopsReading) {
    DeafBroker broker;
    ASSERT_NE(broker.port(), 0);
    auto rig = std::make_unique<Rig>(settings(broker.port()));
    std::string error;
    ASSERT_TRUE(rig->client->start(error)) << error;
    ASSERT_TRUE(rig->run_until([&] { return rig->client->connected(); }, 10s));
    // More than the socket buffers hold: the rest waits in libmosquitto, and the goodbye
    // (status, DISCONNECT) behind it can never be written.
    const std::string big(256 * 1024, 'x');
    for (int i = 0; i < 64; ++i)
        EXPECT_TRUE(rig->client->publish(Message{"t/big", big, 0, false}));
    rig->run_until([] { return false; }, 200ms);
    EXPECT_TRUE(rig->client->connected());
    EXPECT_TRUE(stops_within(rig, 10s));
}

// TLS through loop_read/loop_write against the real mosquitto: 8 MiB in 32 messages, more
// than the socket takes at once (SSL_write wants the socket writable again), all arrive
// whole and in order.
TEST(MqttClient, LargeMessagesOverTlsArriveWhole) {
    test::ScratchDir dir("mqtt-tls-large");
    if (!test::make_tls(dir)) GTEST_SKIP() << "openssl could not make the TLS files";
    const std::string d = dir.path().string();
    test::Mosquitto broker(dir.path(), "cafile " + d + "/ca.crt\ncertfile " + d +
                                           "/server.crt\nkeyfile " + d + "/server.key\n");
    if (!broker.started()) GTEST_SKIP() << "mosquitto is not installed";
    test::Recorder sub(broker.port(), "t/big", {d + "/ca.crt", "", "", ""});
    ASSERT_TRUE(sub.connected());
    auto m = settings(broker.port());
    m.ca_file = d + "/ca.crt";
    auto rig = std::make_unique<Rig>(m);
    std::string error;
    ASSERT_TRUE(rig->client->start(error)) << error;
    ASSERT_TRUE(rig->run_until([&] { return rig->client->connected(); }, 10s));
    constexpr int n = 32;
    for (int i = 0; i < n; ++i) {
        std::string payload(256 * 1024, static_cast<char>('a' + i % 26));
        EXPECT_TRUE(rig->client->publish(Message{"t/big", std::move(payload), 1, false}));
    }
    ASSERT_TRUE(rig->run_until([&] { return sub.count() >= static_cast<std::size_t>(n); }, 30s))
        << sub.count() << " of " << n;
    const auto got = sub.messages();
    for (int i = 0; i < n; ++i)
        EXPECT_EQ(got[static_cast<std::size_t>(i)].payload,
                  std::string(256 * 1024, static_cast<char>('a' + i % 26)))
            << "message " << i;
    EXPECT_TRUE(stops_within(rig, 10s));
}

// fins-bridge itself, against a broker that never answers: SIGTERM ends it with exit code 0
// (SIGKILL after 20 s would be 137).
TEST(MqttClient, FinsBridgeEndsOnSigtermWhenItsBrokerNeverAnswers) {
    test::ScratchDir dir("mqtt-silent-bridge");
    SilentBroker broker(true);
    ASSERT_NE(broker.port(), 0);
    const auto file =
        dir.write("bridge.toml", test::mqtt_section(broker.port()) +
                                     "[[plc]]\nname = \"p\"\nhost = \"127.0.0.1\"\nport = 9\n"
                                     "[[plc.group]]\nname = \"g\"\n"
                                     "tags = [{name=\"a\",address=\"D0\",type=\"int16\"}]\n");
    test::Child bridge(
        {test::bridge_path, "--config", file, "--log-level", "info", "--instance", "test"},
        dir.path() / "bridge.log");
    // Its signal handler is in place once it says it polls.
    ASSERT_TRUE(bridge.wait_for_stderr("polling", 20s)) << bridge.log();
    EXPECT_EQ(bridge.kill(SIGTERM, 20s), 0) << bridge.log();
}

}  // namespace
}  // namespace fins::bridge
