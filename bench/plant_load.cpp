// fins_plant_load: (1) the relayed 1-word read rate through two routers at 32 in flight,
// as a ratio of the direct rate in the same run (three-network plant of
// examples/three-networks.toml on free ports; --relay false skips it); (2) a plant of
// --nodes CJ2H CPU Units, 250 per network on at least 4 networks (127.0.20.x,
// 127.0.21.x ...; --tcp false: FINS/UDP only): time until every unit is bound, RSS, a
// first round reading 10 words from each unit one at a time (its answer must come from
// its own address and node), RSS then, and the poll rate over every unit at 64 in flight
// for --seconds (docs/benchmarks.md "A site of 10,000 CPU Units"). Exit 1 when a unit
// did not answer.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/client.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "server/routing/plant.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace {

using Clock = std::chrono::steady_clock;

long rss_kib() {
    std::ifstream f("/proc/self/status");
    for (std::string line; std::getline(f, line);)
        if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
    return -1;
}

fins::server::PlantPortConfig unit(std::uint8_t n, std::uint8_t network, std::string bind) {
    fins::server::PlantPortConfig p;
    p.unit_number = n;
    p.network = network;
    p.bind = std::move(bind);
    p.port = 0;
    return p;
}

double rate(std::uint16_t port, const std::string& host, fins::NodeAddress dest, double seconds) {
    fins::ClientOptions o;
    o.host = host;
    o.port = port;
    o.destination = dest;
    o.timeout = std::chrono::milliseconds(1000);
    auto c = fins::Client::connect(o);
    if (!c) return 0;
    const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(seconds));
    std::size_t done = 0;
    std::function<void()> issue = [&] {
        (*c)->async_send(fins::MemoryAreaRead{{0x82, 0, 0}, 1},
                         [&](fins::Result<fins::MemoryAreaReadResponse> r) {
                             if (r) ++done;
                             if (Clock::now() < end) issue();
                         });
    };
    const auto start = Clock::now();
    for (int i = 0; i < 32; ++i)
        issue();
    (*c)->run();
    return static_cast<double>(done) / std::chrono::duration<double>(Clock::now() - start).count();
}

// One unit of the large plant as the poller sees it.
struct Target {
    fins::NodeAddress address;
    sockaddr_in peer{};
};

struct Round {
    std::size_t answered = 0;  // normal completion, 10 words, from the unit's own node
    std::size_t lost = 0;      // no answer within a second
};

// Reads D0-D9 (01 01) from every target over one UDP socket, `window` in flight; an
// answer counts when it comes from the target's address with its node as the source
// (target i is network 1 + i % networks, node 1 + i / networks).
Round poll_round(const std::vector<Target>& targets, unsigned networks, std::size_t window) {
    Round round;
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) return round;
    std::vector<std::uint8_t> in_flight(targets.size(), 0);
    std::size_t next = 0, outstanding = 0;
    std::uint8_t sid = 0;
    std::array<std::uint8_t, 2048> buffer{};
    const std::array<std::uint8_t, 6> read10{0x82, 0, 0, 0, 0, 10};
    while (next < targets.size() || outstanding > 0) {
        while (outstanding < window && next < targets.size()) {
            fins::Header h;
            h.destination = targets[next].address;
            h.source = {0, 254, 0};
            h.service_id = static_cast<std::uint8_t>(++sid);
            std::array<std::uint8_t, 64> frame{};
            const auto n = fins::encode_request(h, {0x01, 0x01}, fins::Bytes(read10),
                                                fins::MutableBytes(frame));
            const auto& to = targets[next].peer;
            if (n && ::sendto(fd, frame.data(), *n, 0, reinterpret_cast<const sockaddr*>(&to),
                              sizeof to) == static_cast<ssize_t>(*n)) {
                in_flight[next] = 1;
                ++outstanding;
            } else {
                ++round.lost;
            }
            ++next;
        }
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 1000) <= 0) {
            round.lost += outstanding;  // a second without any answer: give up on them
            break;
        }
        sockaddr_in from{};
        socklen_t size = sizeof from;
        const auto got = ::recvfrom(fd, buffer.data(), buffer.size(), 0,
                                    reinterpret_cast<sockaddr*>(&from), &size);
        if (got <= 0) continue;
        const auto r =
            fins::decode_response(fins::Bytes(buffer.data(), static_cast<std::size_t>(got)));
        if (!r) continue;
        const auto source = r->header.source;
        // Unit i is network 1 + i % networks, node 1 + i / networks.
        if (source.network == 0 || source.node == 0) continue;
        const std::size_t i = (source.node - 1u) * networks + (source.network - 1u);
        if (i >= targets.size() || in_flight[i] == 0 ||
            targets[i].peer.sin_addr.s_addr != from.sin_addr.s_addr)
            continue;
        in_flight[i] = 0;
        --outstanding;
        if (r->code.ok() && r->data.size() == 20) ++round.answered;
    }
    ::close(fd);
    return round;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_plant_load: relayed read rate and a plant of many nodes"};
    double seconds = 2.0;
    unsigned nodes = 1000;
    app.add_option("--seconds", seconds, "Duration of each rate case")->capture_default_str();
    app.add_option("--nodes", nodes, "CPU Units of the large plant (0: skip)")
        ->capture_default_str()
        ->check(CLI::Range(0u, 127u * 250u));
    bool tcp = true;
    bool relay = true;
    app.add_option("--tcp", tcp, "Each unit of the large plant listens on FINS/TCP too")
        ->capture_default_str();
    app.add_option("--relay", relay, "Measure the relay rate first")->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    spdlog::set_level(spdlog::level::warn);

    if (relay) {
        fins::server::PlantConfig c;
        fins::server::PlantCpuConfig a, b, line;
        a.name = "router-a";
        a.ports = {unit(0, 1, "127.0.1.1"), unit(1, 2, "127.0.2.1")};
        a.relays = {{3, 2, 2}};
        b.name = "router-b";
        b.ports = {unit(0, 2, "127.0.2.2"), unit(1, 3, "127.0.3.2")};
        b.relays = {{1, 2, 1}};
        line.name = "line-3";
        line.ports = {unit(0, 3, "127.0.3.5")};
        line.relays = {{1, 3, 2}, {2, 3, 2}};
        c.cpus = {a, b, line};
        asio::io_context io{1};
        auto plant = fins::server::Plant::start(io, c);
        if (!plant) return 1;
        std::thread t([&] { io.run(); });
        const double direct =
            rate((*plant)->server(2, 0).udp_port(), "127.0.3.5", {3, 5, 0}, seconds);
        const double relayed =
            rate((*plant)->server(0, 0).udp_port(), "127.0.1.1", {3, 5, 0}, seconds);
        std::printf(
            "relay: direct %.0f/s, through two routers %.0f/s, ratio %.2f (32 in flight, UDP)\n",
            direct, relayed, direct > 0 ? relayed / direct : 0.0);
        asio::post(io, [&] {
            (*plant)->stop();
            io.stop();
        });
        t.join();
    }
    if (nodes == 0) return 0;

    // 250 nodes per network (127.0.20.x, 127.0.21.x ...), at least 4 networks.
    const unsigned networks = std::max(4u, (nodes + 249) / 250);
    const auto address_of = [&](unsigned i) {
        return fins::NodeAddress{static_cast<std::uint8_t>(1 + i % networks),
                                 static_cast<std::uint8_t>(1 + i / networks), 0};
    };
    const long rss_before = rss_kib();
    fins::server::PlantConfig c;
    c.cpus.reserve(nodes);
    for (unsigned i = 0; i < nodes; ++i) {
        fins::server::PlantCpuConfig cpu;
        cpu.name = fmt::format("n{}", i);
        const auto a = address_of(i);
        cpu.ports = {unit(0, a.network, fmt::format("127.0.{}.{}", 19 + a.network, a.node))};
        cpu.ports[0].tcp = tcp;
        c.cpus.push_back(std::move(cpu));
    }
    const auto t0 = Clock::now();
    asio::io_context io{1};
    auto plant = fins::server::Plant::start(io, c);
    if (!plant) {
        std::fprintf(stderr, "start: %s\n", plant.error().message().c_str());
        return 1;
    }
    const double start_s = std::chrono::duration<double>(Clock::now() - t0).count();
    const long rss_started = rss_kib();
    std::thread t([&] { io.run(); });

    std::vector<Target> targets(nodes);
    for (unsigned i = 0; i < nodes; ++i) {
        const auto a = address_of(i);
        auto& to = targets[i];
        to.address = a;
        to.peer.sin_family = AF_INET;
        to.peer.sin_port = htons((*plant)->server(i, 0).udp_port());
        to.peer.sin_addr.s_addr = htonl((127u << 24) | ((19u + a.network) << 8) | a.node);
    }
    // First round: every unit answers its own 10 words, from its own node.
    const auto p0 = Clock::now();
    const Round first = poll_round(targets, networks, 1);
    const double first_s = std::chrono::duration<double>(Clock::now() - p0).count();
    const long rss_polled = rss_kib();
    // Then the poll rate: rounds over every unit, 64 reads in flight, for --seconds.
    std::size_t reads = 0, lost = 0;
    const auto r0 = Clock::now();
    const auto until =
        r0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    while (Clock::now() < until) {
        const auto r = poll_round(targets, networks, 64);
        reads += r.answered;
        lost += r.lost;
    }
    const double rate_s = std::chrono::duration<double>(Clock::now() - r0).count();
    std::printf(
        "plant of %u CJ2H on %u networks (%s): started and bound in %.2f s, RSS %ld MiB "
        "(process before: %ld MiB); %zu/%u answered 10 words from their own node in %.2f s "
        "(one at a time), RSS then %ld MiB; poll rate %.0f reads/s (64 in flight, %zu "
        "unanswered)\n",
        nodes, networks, tcp ? "UDP+TCP" : "UDP only", start_s, rss_started / 1024,
        rss_before / 1024, first.answered, nodes, first_s, rss_polled / 1024,
        static_cast<double>(reads) / rate_s, lost);
    asio::post(io, [&] {
        (*plant)->stop();
        io.stop();
    });
    t.join();
    return first.answered == nodes ? 0 : 1;
}
