// A plant in the test process: server::Plant on its own io_context thread. The default
// is the three-network plant of examples/three-networks.toml on free ports:
//   router-a 1.1 (127.0.1.1) | 2.1 (127.0.2.1)     relay: 3 via 2.2
//   router-b 2.2 (127.0.2.2) | 3.2 (127.0.3.2)     relay: 1 via 2.1
//   line-3   3.5 (127.0.3.5)                        relay: 1 and 2 via 3.2
// Tests talk to it only through sockets.
#pragma once

#include <memory>
#include <string>
#include <thread>
#include <utility>

#include <gtest/gtest.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/client.hpp"
#include "server/routing/plant.hpp"
#include "server/routing/router.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::test {

inline server::PlantPortConfig plant_port(std::uint8_t unit, std::uint8_t network,
                                          std::string bind) {
    server::PlantPortConfig p;
    p.unit_number = unit;
    p.network = network;
    p.bind = std::move(bind);
    p.port = 0;
    return p;
}

inline server::PlantConfig three_networks() {
    server::PlantConfig c;
    server::PlantCpuConfig a;
    a.name = "router-a";
    a.ports = {plant_port(0, 1, "127.0.1.1"), plant_port(1, 2, "127.0.2.1")};
    a.relays = {{3, 2, 2}};
    server::PlantCpuConfig b;
    b.name = "router-b";
    b.ports = {plant_port(0, 2, "127.0.2.2"), plant_port(1, 3, "127.0.3.2")};
    b.relays = {{1, 2, 1}};
    server::PlantCpuConfig line;
    line.name = "line-3";
    line.ports = {plant_port(0, 3, "127.0.3.5")};
    line.relays = {{1, 3, 2}, {2, 3, 2}};
    c.cpus = {a, b, line};
    return c;
}

// three_networks() as two processes would run it: the two routers, and line-3 alone,
// every unit on the same fixed `port` (as on a real network), so router-b reaches
// 127.0.3.5 over FINS/UDP by its node-address table.
inline std::pair<server::PlantConfig, server::PlantConfig> routers_and_line(std::uint16_t port) {
    auto routers = three_networks();
    routers.cpus.pop_back();
    auto line = three_networks();
    line.cpus.erase(line.cpus.begin(), line.cpus.begin() + 2);
    for (auto* c : {&routers, &line})
        for (auto& cpu : c->cpus)
            for (auto& p : cpu.ports)
                p.port = port;
    return {std::move(routers), std::move(line)};
}

class PlantThread {
  public:
    explicit PlantThread(const server::PlantConfig& config = three_networks()) {
        const auto problem = server::validate_plant(config);
        if (!problem.empty()) throw std::runtime_error(problem);
        auto p = server::Plant::start(io_, config);
        if (!p) throw std::runtime_error("plant start: " + p.error().message());
        plant_ = std::move(*p);
        thread_ = std::thread([this] { io_.run(); });
    }
    ~PlantThread() {
        asio::post(io_, [this] {
            plant_->stop();
            io_.stop();
        });
        thread_.join();
    }
    // Fixed at start: the bind address and port of unit `port` of CPU Unit `cpu`.
    [[nodiscard]] std::uint16_t port(std::size_t cpu, std::size_t unit = 0) const {
        auto& s = plant_->server(cpu, unit);
        return s.tcp_port() != 0 ? s.tcp_port() : s.udp_port();
    }

    std::unique_ptr<Client> client(const std::string& host, std::uint16_t port,
                                   NodeAddress destination, bool tcp = false,
                                   ClientOptions o = {}) {
        o.host = host;
        o.port = port;
        o.destination = destination;
        o.protocol = tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
        if (o.timeout == ClientOptions{}.timeout) o.timeout = std::chrono::milliseconds(1500);
        o.retries = 0;
        auto c = Client::connect(o);
        EXPECT_TRUE(c.has_value()) << (c ? "" : c.error().message());
        return c ? std::move(*c) : nullptr;
    }
    // The plant itself: read it only while its thread is idle (after an answer came).
    server::Plant& plant() noexcept { return *plant_; }
    // A client on network 1 at router-a's port.
    std::unique_ptr<Client> from_network_1(NodeAddress destination, bool tcp = false) {
        return client("127.0.1.1", port(0), destination, tcp);
    }

  private:
    asio::io_context io_{1};
    std::unique_ptr<server::Plant> plant_;
    std::thread thread_;
};

}  // namespace fins::test
