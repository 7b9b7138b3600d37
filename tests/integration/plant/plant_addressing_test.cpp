// Node-address methods per Ethernet unit (W596 2-3, W420 5-2; README "Node-address
// methods"): where line-3 (127.0.3.5) sends the answer to a command from node 77 of its
// network that came from 127.0.0.1 (another address than node 77's).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <string>

#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"
#include "integration/support/plant_fixture.hpp"

namespace fins::test {
namespace {

class Udp {
  public:
    Udp(const std::string& ip, std::uint16_t port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
        sockaddr_in a = address(ip, port);
        EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    }
    ~Udp() { ::close(fd_); }
    Udp(const Udp&) = delete;
    Udp& operator=(const Udp&) = delete;

    static sockaddr_in address(const std::string& ip, std::uint16_t port) {
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_port = htons(port);
        ::inet_pton(AF_INET, ip.c_str(), &a.sin_addr);
        return a;
    }
    void send(const std::string& ip, std::uint16_t port, const std::vector<std::uint8_t>& b) {
        const sockaddr_in a = address(ip, port);
        ASSERT_EQ(
            ::sendto(fd_, b.data(), b.size(), 0, reinterpret_cast<const sockaddr*>(&a), sizeof a),
            static_cast<ssize_t>(b.size()));
    }
    // A datagram within `ms`, or none.
    bool receive(int ms) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, ms) != 1) return false;
        std::array<std::uint8_t, 2048> buf{};
        return ::recv(fd_, buf.data(), buf.size(), 0) > 0;
    }

  private:
    int fd_;
};

// 01 01 MEMORY AREA READ D0, 1 word, from node NET.NODE (default 3.77) to DNA.5.
std::vector<std::uint8_t> read_from_node_77(std::uint8_t node = 77, std::uint8_t network = 3,
                                            std::uint8_t destination_network = 3) {
    return {0x80, 0x00, 0x02,    destination_network,
            0x05, 0x00, network, node,
            0x00, 0x42, 0x01,    0x01,
            0x82, 0x00, 0x00,    0x00,
            0x00, 0x01};
}

// Where the answer arrives: at the sender (127.0.0.1) or at node 77's generated address
// (127.0.3.77, line-3's port), or at a listed address (127.0.3.78).
struct Arrivals {
    bool sender = false;
    bool generated = false;
    bool listed = false;
};

Arrivals answer_for(server::AddressMethod method, bool dynamic, bool listed_77,
                    const std::vector<std::uint8_t>& frame = read_from_node_77()) {
    auto config = three_networks();
    auto& unit = config.cpus[2].ports[0];
    unit.method = method;
    unit.dynamic_remote_ip = dynamic;
    if (listed_77) unit.ip_table.push_back({77, {127, 0, 3, 78}});
    PlantThread plant(config);
    const auto port = plant.port(2);
    Udp generated("127.0.3.77", port);
    Udp listed("127.0.3.78", port);
    Udp sender("127.0.0.1", 0);
    sender.send("127.0.3.5", port, frame);
    Arrivals a;
    a.sender = sender.receive(500);
    a.generated = generated.receive(a.sender ? 50 : 500);
    a.listed = listed.receive(50);
    return a;
}

TEST(PlantAddressing, W596_2_3_AutomaticDynamicAnswersTheSource) {
    const auto a = answer_for(server::AddressMethod::automatic_dynamic, true, false);
    EXPECT_TRUE(a.sender);
    EXPECT_FALSE(a.generated);
}

TEST(PlantAddressing, W596_2_3_AutomaticStaticAnswersTheGeneratedAddress) {
    const auto a = answer_for(server::AddressMethod::automatic_static, true, false);
    EXPECT_FALSE(a.sender);
    EXPECT_TRUE(a.generated);
}

TEST(PlantAddressing, W596_2_3_DoNotConvertKeepsTheGeneratedAddress) {
    const auto a = answer_for(server::AddressMethod::automatic_dynamic, false, false);
    EXPECT_FALSE(a.sender);
    EXPECT_TRUE(a.generated);
}

TEST(PlantAddressing, W596_2_3_TableAnswersTheListedAddress) {
    const auto a = answer_for(server::AddressMethod::table, true, true);
    EXPECT_FALSE(a.sender);
    EXPECT_TRUE(a.listed);
}

TEST(PlantAddressing, W596_2_3_TableLearnsAnUnlistedNode) {
    const auto a = answer_for(server::AddressMethod::table, true, false);
    EXPECT_TRUE(a.sender);
}

TEST(PlantAddressing, W596_2_3_TableWithoutConversionCannotAnswerAnUnlistedNode) {
    const auto a = answer_for(server::AddressMethod::table, false, false);
    EXPECT_FALSE(a.sender);
    EXPECT_FALSE(a.generated);
    EXPECT_FALSE(a.listed);
}

TEST(PlantAddressing, W596_2_3_CombinedPrefersTheTable) {
    EXPECT_TRUE(answer_for(server::AddressMethod::combined, true, true).listed);
    const auto a = answer_for(server::AddressMethod::combined, false, false);
    EXPECT_TRUE(a.generated);
}

// Issue 26 point 14, one rule for SA1 = 0 (the npm omron-fins client's default): node 0
// is no remote node (fins-frames.md 1.3: SA1 00 is "internal communications inside the
// local PLC", nodes are 01-FE), so W596 2-3's conversion has no entry for it, and a
// FINS/UDP unit answers where the request came from (fins-frames.md 2, "Reply
// destination"), as a single finsd does: under every method, with or without
// conversion, addressed with DNA 0 or the unit's own network, SNA 0 or the network.
TEST(PlantAddressing, W596_2_3_SourceNode0IsAnsweredWhereTheRequestCameFrom) {
    using M = server::AddressMethod;
    for (const auto method : {M::automatic_dynamic, M::automatic_static, M::table, M::combined})
        for (const bool dynamic : {true, false})
            for (const std::uint8_t dna : {std::uint8_t{0}, std::uint8_t{3}})
                for (const std::uint8_t sna : {std::uint8_t{0}, std::uint8_t{3}}) {
                    SCOPED_TRACE(::testing::Message()
                                 << "method " << static_cast<int>(method) << " dynamic " << dynamic
                                 << " DNA " << int{dna} << " SNA " << int{sna});
                    const auto a =
                        answer_for(method, dynamic, false, read_from_node_77(0, sna, dna));
                    EXPECT_TRUE(a.sender);
                    EXPECT_FALSE(a.generated);
                }
    // The single node (finsd without a plant, node 5 on 127.0.0.1): the same frame on the
    // local network, the same answer at the sender.
    Finsd single({"--node", "5"});
    ASSERT_TRUE(single.started()) << single.result().err;
    Udp sender("127.0.0.1", 0);
    sender.send("127.0.0.1", single.port(), read_from_node_77(0, 0, 0));
    EXPECT_TRUE(sender.receive(2000));
    EXPECT_EQ(single.stop().exit_code, 0);
}

}  // namespace
}  // namespace fins::test
