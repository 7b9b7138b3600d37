// A site in one finsd (issue 19, docs/networks.md "A plant of 10,000 CPU Units"): a
// `repeat` [[plc]] of 40 networks x 250 nodes starts and every one of the 10,000 CPU
// Units answers 05 01 (CPU UNIT DATA READ) from its own address with its own network and
// node; the open-files limit is raised for a plant that needs it, and a plant that cannot
// fit under the hard limit is refused at start with the count, not at its 9,000th unit.
// Correctness only: the start time and RSS are docs/benchmarks.md's (fins_plant_load).
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

#include "fins/frame.hpp"
#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

// A port no one holds now, for every unit of the plant (each on its own address).
std::uint16_t free_udp_port() {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t size = sizeof a;
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &size);
    ::close(fd);
    return ntohs(a.sin_port);
}

// The plant: networks first-last, nodes 1-`nodes` each, on 127.0.NETWORK.NODE:port.
std::string plant_config(int first, int last, int nodes, std::uint16_t port, bool tcp) {
    return "[[plc]]\n"
           "name = \"cell-{network}-{node}\"\n"
           "repeat = { networks = \"" +
           std::to_string(first) + "-" + std::to_string(last) + "\", nodes = \"1-" +
           std::to_string(nodes) +
           "\" }\n"
           "[[plc.ethernet]]\n"
           "bind = \"127.0.{network}.{node}\"\n"
           "port = " +
           std::to_string(port) + "\ntcp = " + (tcp ? "true" : "false") + "\n";
}

struct Unit {
    std::uint8_t network;
    std::uint8_t node;
};

// Sends 05 01 to every unit over one UDP socket, 64 in flight; counts the answers with
// normal completion that came from the unit's own address, with the unit's network and
// node as their source and this request's SID. Bounded: a second without any answer
// ends the round.
std::size_t units_answering_0501(const std::vector<Unit>& units, std::uint16_t port) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) return 0;
    std::vector<bool> waiting(units.size(), false);
    std::size_t next = 0, outstanding = 0, answered = 0;
    std::array<std::uint8_t, 2048> buffer{};
    const auto key = [](std::uint8_t network, std::uint8_t node) {
        return (static_cast<std::uint32_t>(network) << 8) | node;
    };
    std::vector<std::size_t> index_of(1u << 16, units.size());
    for (std::size_t i = 0; i < units.size(); ++i)
        index_of[key(units[i].network, units[i].node)] = i;
    while (next < units.size() || outstanding > 0) {
        while (outstanding < 64 && next < units.size()) {
            const auto& u = units[next];
            Header h;
            h.destination = {u.network, u.node, 0};
            h.source = {0, 254, 0};
            h.service_id = static_cast<std::uint8_t>(u.node);
            std::array<std::uint8_t, 32> frame{};
            const std::array<std::uint8_t, 1> parameters{0x00};  // the whole data
            const auto n = encode_request(h, {0x05, 0x01}, parameters, frame);
            sockaddr_in to{};
            to.sin_family = AF_INET;
            to.sin_port = htons(port);
            to.sin_addr.s_addr = htonl((127u << 24) | (u.network * 1u << 8) | u.node);
            if (n && ::sendto(fd, frame.data(), *n, 0, reinterpret_cast<const sockaddr*>(&to),
                              sizeof to) == static_cast<ssize_t>(*n)) {
                waiting[next] = true;
                ++outstanding;
            }
            ++next;
        }
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 1000) != 1) break;
        sockaddr_in from{};
        socklen_t size = sizeof from;
        const auto got = ::recvfrom(fd, buffer.data(), buffer.size(), 0,
                                    reinterpret_cast<sockaddr*>(&from), &size);
        if (got <= 0) continue;
        const auto r = decode_response(Bytes(buffer.data(), static_cast<std::size_t>(got)));
        if (!r) continue;
        const auto i = index_of[key(r->header.source.network, r->header.source.node)];
        if (i == units.size() || !waiting[i]) continue;
        waiting[i] = false;
        --outstanding;
        const auto& u = units[i];
        const std::uint32_t own = (127u << 24) | (u.network * 1u << 8) | u.node;
        if (r->command == CommandCode{0x05, 0x01} && r->code.ok() && r->header.source.unit == 0 &&
            r->header.service_id == u.node && ntohl(from.sin_addr.s_addr) == own &&
            ntohs(from.sin_port) == port && !r->data.empty())
            ++answered;
    }
    ::close(fd);
    return answered;
}

std::vector<Unit> units_of(int first, int last, int nodes) {
    std::vector<Unit> units;
    for (int network = first; network <= last; ++network)
        for (int node = 1; node <= nodes; ++node)
            units.push_back({static_cast<std::uint8_t>(network), static_cast<std::uint8_t>(node)});
    return units;
}

// finsd under `sh -c "ulimit ... && exec finsd --config FILE"`, waiting up to `wait` for
// its "listening" line (an ASan build of 10,000 units takes a while to start).
FinsdOptions limited(const std::string& limits, std::chrono::seconds wait) {
    return {.port = std::nullopt, .shell = limits, .wait = wait};
}

TEST(PlantScale, TenThousandCpuUnitsEachAnswer0501WithTheirOwnNode) {
    ScratchDir dir("plant-scale");
    const auto port = free_udp_port();
    // 40 networks x 250 nodes on 127.0.88-127.x (no other test's addresses), FINS/UDP
    // only: 10,000 descriptors, under this machine's limit of open files.
    const auto config = dir.write("site.toml", plant_config(88, 127, 250, port, false));
    Finsd finsd({"--config", config}, limited("", std::chrono::seconds(90)));
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    const auto units = units_of(88, 127, 250);
    ASSERT_EQ(units.size(), 10'000u);
    EXPECT_EQ(units_answering_0501(units, port), units.size());
    EXPECT_EQ(finsd.stop(SIGTERM, std::chrono::seconds(60)).exit_code, 0);
}

TEST(PlantScale, TheOpenFilesLimitIsRaisedForAPlantThatNeedsIt) {
    ScratchDir dir("plant-scale");
    const auto port = free_udp_port();
    // 150 units with FINS/UDP and FINS/TCP: 300 sockets, over a soft limit of 100, under
    // the hard limit of 500.
    const auto config = dir.write("plant.toml", plant_config(88, 88, 150, port, true));
    Finsd finsd({"--config", config},
                limited("ulimit -S -n 100 && ulimit -H -n 500 && ", std::chrono::seconds(30)));
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    EXPECT_EQ(units_answering_0501(units_of(88, 88, 150), port), 150u);
    EXPECT_EQ(finsd.stop(SIGTERM, std::chrono::seconds(30)).exit_code, 0);
}

TEST(PlantScale, APlantOverTheHardLimitIsRefusedWithTheCount) {
    ScratchDir dir("plant-scale");
    // 250 units with both transports need 500 sockets; the hard limit is 300.
    const auto config = dir.write("plant.toml", plant_config(88, 88, 250, free_udp_port(), true));
    Finsd finsd({"--config", config}, limited("ulimit -n 300 && ", std::chrono::seconds(30)));
    ASSERT_FALSE(finsd.started());
    const auto& result = finsd.result();
    EXPECT_EQ(result.exit_code, 3);
    EXPECT_NE(result.err.find("the plant needs"), std::string::npos) << result.err;
    EXPECT_NE(result.err.find("500 for its units' sockets"), std::string::npos) << result.err;
    EXPECT_NE(result.err.find("the limit is 300"), std::string::npos) << result.err;
}

}  // namespace
}  // namespace fins::test
