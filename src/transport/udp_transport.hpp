// FINS/UDP client transport (frames section 2): one connected UDP socket to host:port,
// one datagram = one FINS frame. IPv4 and IPv6; the socket's family follows the first
// resolved address that can be connected.
//
// Connecting the socket makes the kernel drop datagrams from other peers. An ICMP
// "port unreachable" (ECONNREFUSED on the next receive) does not close the transport:
// UDP has no connection, the request simply times out and is retried (W596 SendCmd,
// p. 3-16).
// Datagrams longer than 2,012 bytes are dropped. LinkInfo nodes come from
// node_from_address() of the local and the peer address.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include <asio/io_context.hpp>
#include <asio/ip/udp.hpp>
#include <asio/steady_timer.hpp>

#include "fins/frame.hpp"
#include "transport/transport.hpp"
#include "transport/write_queue.hpp"

namespace fins::transport {

class UdpTransport final : public Transport {
  public:
    UdpTransport(asio::io_context& io, TransportOptions options);
    ~UdpTransport() override;

    void async_open(OpenHandler done) override;
    void send(Bytes frame) override;
    void close() override;
    [[nodiscard]] State state() const noexcept override { return state_; }
    [[nodiscard]] bool write_pending() const noexcept override { return !queue_.empty(); }

  private:
    void connect_first(const asio::ip::udp::resolver::results_type& results);
    void finish_open(Result<LinkInfo> result);
    void receive();
    void write_next();
    void fail(std::error_code reason);

    TransportOptions options_;
    asio::ip::udp::resolver resolver_;
    asio::ip::udp::socket socket_;
    asio::steady_timer open_timer_;
    State state_ = State::closed;
    std::uint64_t generation_ = 0;  // bumped on close: handlers of older sockets ignore
    std::shared_ptr<int> life_ = std::make_shared<int>(0);  // handlers check it is alive
    OpenHandler open_done_;
    WriteQueue queue_;
    bool writing_ = false;
    std::array<std::uint8_t, max_frame_size + 1> rx_{};
};

}  // namespace fins::transport
