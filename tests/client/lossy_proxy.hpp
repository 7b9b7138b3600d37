// A UDP proxy on 127.0.0.1 (port 0) between one client and one server that drops,
// duplicates and delays datagrams in both directions. Each datagram's fate comes from a
// seeded PRNG, in arrival order, so a run's faults are repeatable as far as the arrival
// order is. Runs on its own thread; counts() is safe to call from the test thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>

#include "transport/asio.hpp"

namespace fins::test {

struct Faults {
    double drop = 0.20;       // lost
    double duplicate = 0.05;  // sent twice at once
    double delay = 0.10;      // held back for a random time up to max_delay, then sent
    std::chrono::milliseconds max_delay{60};
    std::uint32_t seed = 1;
};

class LossyUdpProxy {
  public:
    struct Counts {
        std::uint64_t forwarded = 0;
        std::uint64_t dropped = 0;
        std::uint64_t duplicated = 0;
        std::uint64_t delayed = 0;
    };

    LossyUdpProxy(std::uint16_t server_port, Faults faults);
    ~LossyUdpProxy();
    LossyUdpProxy(const LossyUdpProxy&) = delete;
    LossyUdpProxy& operator=(const LossyUdpProxy&) = delete;

    [[nodiscard]] std::uint16_t port() const noexcept { return port_; }
    Counts counts();

  private:
    void receive_front();
    void receive_back();
    // Applies the faults to one datagram going to the server (to_server) or the client.
    void pass(std::vector<std::uint8_t> datagram, bool to_server);
    void emit(const std::vector<std::uint8_t>& datagram, bool to_server);

    asio::io_context io_;
    asio::ip::udp::socket front_;  // faces the client
    asio::ip::udp::socket back_;   // connected to the server
    asio::ip::udp::endpoint client_;
    asio::ip::udp::endpoint from_;
    bool have_client_ = false;
    std::array<std::uint8_t, 4096> front_buffer_{};
    std::array<std::uint8_t, 4096> back_buffer_{};
    Faults faults_;
    std::mt19937 rng_;
    std::mutex mutex_;
    Counts counts_;
    std::uint16_t port_ = 0;
    std::thread thread_;
};

}  // namespace fins::test
