#pragma once
// A UDP socket with deadlines for `fins probe` and `fins discover`: one datagram out, the
// answers in until a deadline, on Asio so that the same code runs on Linux and Windows
// (docs/windows.md). Not for the FINS client itself (that is fins::Client's transport).
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <system_error>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>

#include "fins/error.hpp"

namespace fins::cli {

class UdpSocket {
  public:
    using Endpoint = boost::asio::ip::udp::endpoint;

    UdpSocket() = default;
    UdpSocket(const UdpSocket&) = delete;
    UdpSocket& operator=(const UdpSocket&) = delete;

    // An unconnected IPv4 socket (`discover`'s sweep).
    std::error_code open_v4();
    // Resolves host:port and connects to its first address (`probe`).
    std::error_code connect(const std::string& host, std::uint16_t port);
    // The local IPv4 address's bytes, when there is one.
    [[nodiscard]] std::optional<std::uint32_t> local_v4() const;

    std::error_code send(std::span<const std::uint8_t> datagram);
    std::error_code send_to(std::uint32_t ipv4, std::uint16_t port,
                            std::span<const std::uint8_t> datagram);

    // Waits up to `left` for a datagram and reads it: its size, 0 when none came in time,
    // or an error (an ICMP port unreachable is connection_refused on every system).
    Result<std::size_t> receive(std::span<std::uint8_t> into, std::chrono::milliseconds left,
                                Endpoint* from = nullptr);
    // Reads a datagram already waiting: its size, or nothing.
    std::optional<std::size_t> try_receive(std::span<std::uint8_t> into, Endpoint& from);

  private:
    bool wait_readable(std::chrono::milliseconds left);

    boost::asio::io_context io_;
    boost::asio::ip::udp::socket socket_{io_};
};

}  // namespace fins::cli
