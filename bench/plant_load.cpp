// fins_plant_load: (1) the relayed 1-word read rate through two routers at 32 in flight,
// as a ratio of the direct rate in the same run (three-network plant of
// examples/three-networks.toml on free ports); (2) a plant of --nodes CJ2H CPU Units on
// 4 networks (127.0.20-23.x): time until every unit answers, RSS, and RSS after a client
// polled 10 words from each (docs/benchmarks.md "A plant of several networks").
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/client.hpp"
#include "fins/commands/memory_area.hpp"
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

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_plant_load: relayed read rate and a plant of many nodes"};
    double seconds = 2.0;
    unsigned nodes = 1000;
    app.add_option("--seconds", seconds, "Duration of each rate case")->capture_default_str();
    app.add_option("--nodes", nodes, "CPU Units of the large plant (0: skip)")
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    spdlog::set_level(spdlog::level::warn);

    {
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

    const long rss_before = rss_kib();
    fins::server::PlantConfig c;
    for (unsigned i = 0; i < nodes; ++i) {
        fins::server::PlantCpuConfig cpu;
        cpu.name = fmt::format("n{}", i);
        const auto network = static_cast<std::uint8_t>(1 + i % 4);
        const auto node = 1 + i / 4;
        cpu.ports = {unit(0, network, fmt::format("127.0.{}.{}", 19 + network, node))};
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
    std::size_t ok = 0;
    const auto p0 = Clock::now();
    for (unsigned i = 0; i < nodes; ++i) {
        const auto network = static_cast<std::uint8_t>(1 + i % 4);
        const auto node = static_cast<std::uint8_t>(1 + i / 4);
        fins::ClientOptions o;
        o.host = fmt::format("127.0.{}.{}", 19 + network, node);
        o.port = (*plant)->server(i, 0).udp_port();
        o.destination = {network, node, 0};
        auto cl = fins::Client::connect(o);
        if (cl && (*cl)->read_words(fins::Address{}, 10)) ++ok;
    }
    const double poll_s = std::chrono::duration<double>(Clock::now() - p0).count();
    std::printf(
        "plant of %u CJ2H on 4 networks: started and bound in %.2f s, RSS %ld MiB "
        "(process before: %ld MiB); %zu answered 10 words in %.2f s, RSS then %ld MiB\n",
        nodes, start_s, rss_started / 1024, rss_before / 1024, ok, poll_s, rss_kib() / 1024);
    asio::post(io, [&] {
        (*plant)->stop();
        io.stop();
    });
    t.join();
    return 0;
}
