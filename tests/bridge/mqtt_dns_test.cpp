// Issue 27: fins-bridge looked up a broker's name with libmosquitto's blocking getaddrinfo on
// its one thread: while a DNS server did not answer, the loop stood still (the other MQTT
// connection, timers, SIGTERM). The name is now resolved on Asio's resolver, like a PLC's,
// each of its addresses is tried in turn, and the end does not wait for a lookup.
//
// fins-bridge runs in a mount namespace of its own (unshare, root only) whose
// /etc/resolv.conf names a DNS server of this test's that answers only when the test says
// so, and whose /etc/hosts gives the second broker's name ::1 (where nothing listens)
// before 127.0.0.1 (the broker).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bridge_rig.hpp"

namespace fins::bridge::test {
namespace {

using nlohmann::json;

// A DNS server on 127.0.0.N:53 that answers only when told, then with NXDOMAIN.
class HeldDns {
  public:
    HeldDns() {
        fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        for (int n = 70; n < 90 && fd_ >= 0; ++n) {
            sockaddr_in a{};
            a.sin_family = AF_INET;
            a.sin_port = htons(53);
            a.sin_addr.s_addr = htonl((127U << 24) | static_cast<std::uint32_t>(n));
            if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
                address_ = "127.0.0." + std::to_string(n);
                break;
            }
        }
    }
    ~HeldDns() {
        if (fd_ >= 0) ::close(fd_);
    }
    HeldDns(const HeldDns&) = delete;
    HeldDns& operator=(const HeldDns&) = delete;
    [[nodiscard]] const std::string& address() const { return address_; }

    // Waits (at most `limit`) for a query and keeps it, unanswered.
    bool hold(std::chrono::milliseconds limit) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(limit.count())) <= 0) return false;
        Query q;
        socklen_t size = sizeof q.from;
        const auto n = ::recvfrom(fd_, q.bytes.data(), q.bytes.size(), 0,
                                  reinterpret_cast<sockaddr*>(&q.from), &size);
        if (n < 12) return false;
        q.size = static_cast<std::size_t>(n);
        held_.push_back(q);
        return true;
    }
    // Answers every held query, and those that arrive within `linger`, with NXDOMAIN.
    void refuse_all(std::chrono::milliseconds linger) {
        for (const auto& q : held_)
            refuse(q);
        held_.clear();
        while (hold(linger)) {
            refuse(held_.back());
            held_.clear();
        }
    }

  private:
    struct Query {
        std::array<std::uint8_t, 512> bytes{};
        std::size_t size = 0;
        sockaddr_in from{};
    };
    // The query's header and question, as a response with RCODE 3 and no records.
    void refuse(const Query& q) const {
        std::size_t end = 12;
        while (end < q.size && q.bytes[end] != 0)
            end += 1U + q.bytes[end];
        end += 1 + 4;  // the root label, QTYPE and QCLASS
        if (end > q.size) return;
        auto r = q.bytes;
        r[2] = static_cast<std::uint8_t>(0x80U | (q.bytes[2] & 0x01U));  // QR, RD as asked
        r[3] = 0x83;                                                     // RA, NXDOMAIN
        for (std::size_t i = 6; i < 12; ++i)
            r[i] = 0;  // no answer, authority or additional records
        ::sendto(fd_, r.data(), end, 0, reinterpret_cast<const sockaddr*>(&q.from), sizeof q.from);
    }

    int fd_ = -1;
    std::string address_;
    std::vector<Query> held_;
};

TEST(MqttDns, EachAddressOfABrokersNameIsTriedAndALookupThatHangsDoesNotHoldUpTheEnd) {
    if (::geteuid() != 0 || ::access("/usr/bin/unshare", X_OK) != 0)
        GTEST_SKIP() << "needs root and unshare for a mount namespace";
    ScratchDir dir{"mqtt-dns"};
    HeldDns dns;
    ASSERT_FALSE(dns.address().empty()) << "no loopback address free for port 53";
    Mosquitto broker{dir.path()};
    Finsd finsd{{}};
    ASSERT_TRUE(broker.started() && finsd.started());
    Recorder sub(broker.port(), "t/#");
    ASSERT_TRUE(sub.connected());

    // timeout:30: a lookup the test does not answer takes 30 s to fail on its own.
    const auto resolv = dir.write(
        "resolv.conf", "nameserver " + dns.address() + "\noptions timeout:30 attempts:1\n");
    const auto hosts =
        dir.write("hosts", "127.0.0.1 localhost\n::1 broker.test\n127.0.0.1 broker.test\n");
    const auto config = dir.write(
        "bridge.toml", "[mqtt]\nhosts = [\"held.invalid:" + std::to_string(broker.port()) +
                           "\", \"broker.test:" + std::to_string(broker.port()) +
                           "\"]\ntopic_prefix = \"t\"\nbackoff_min_ms = 50\nbackoff_max_ms = "
                           "200\n" +
                           plc("press1", finsd.port()) + tags);
    const std::vector<std::string> argv{
        "/usr/bin/unshare",
        "--mount",
        "--propagation",
        "private",
        "/bin/sh",
        "-c",
        "mount --bind \"$1\" /etc/resolv.conf && mount --bind \"$2\" /etc/hosts && shift 2 && "
        "exec \"$@\"",
        "sh",
        resolv,
        hosts,
        bridge_path,
        "--config",
        config,
        "--log-level",
        "warn",
        "--instance",
        "test"};
    fins::test::Child bridge(argv, config + ".log");

    // 1. The first broker's name is looked up (held, then NXDOMAIN); the second's has ::1,
    // where nothing listens, then 127.0.0.1: the bridge gets there and polls.
    ASSERT_TRUE(dns.hold(std::chrono::seconds(20))) << bridge.log();
    dns.refuse_all(std::chrono::milliseconds(200));
    EXPECT_TRUE(sub.wait_topic("t/press1/status", [](const json& j) {
        return j.value("state", "") == "online";
    })) << bridge.log();

    // 2. The broker goes: broker.test is refused at both addresses, and held.invalid's lookup
    // is held. SIGTERM still ends the bridge at once, with 0 (blocked in getaddrinfo, or
    // joining the resolver's thread, it would take the 30 s and be killed after 20).
    broker.stop();
    ASSERT_TRUE(dns.hold(std::chrono::seconds(20))) << bridge.log();
    EXPECT_EQ(bridge.kill(SIGTERM, std::chrono::seconds(20)), 0) << bridge.log();
    EXPECT_NE(bridge.log().find("not waiting for the lookup"), std::string::npos) << bridge.log();
}

}  // namespace
}  // namespace fins::bridge::test
