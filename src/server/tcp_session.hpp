// One FINS/TCP connection on the server side (frames section 3.4):
//   1. the client sends NODE ADDRESS DATA SEND (command 0) with its node, 0 = allocate;
//   2. we answer command 1 with the client node and ours, or an error code and close;
//   3. then FRAME SEND (command 2) packets carry FINS frames both ways.
// A bad envelope (magic, length, unknown or out-of-sequence command) is answered with
// FRAME SEND ERROR NOTIFICATION (command 3) and the connection is closed.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include <asio/ip/tcp.hpp>

#include "fins/error.hpp"
#include "fins/tcp.hpp"

namespace fins::server {

class Dispatcher;

// The connection table the sessions share: which client nodes are taken.
class TcpNodeTable {
  public:
    TcpNodeTable(std::uint8_t server_node, std::size_t max_connections) noexcept
        : server_node_(server_node), max_connections_(max_connections) {}

    // Claims `requested` (0 = allocate one). Returns the node or the envelope error.
    Result<std::uint8_t> claim(std::uint8_t requested) noexcept;
    void release(std::uint8_t node) noexcept;
    [[nodiscard]] std::size_t in_use() const noexcept { return count_; }
    [[nodiscard]] bool full() const noexcept { return count_ >= max_connections_; }

  private:
    std::array<bool, 256> used_{};
    std::uint8_t server_node_;
    std::size_t max_connections_;
    std::size_t count_ = 0;
};

class TcpSession : public std::enable_shared_from_this<TcpSession> {
  public:
    TcpSession(asio::ip::tcp::socket socket, Dispatcher& dispatcher, TcpNodeTable& nodes);
    ~TcpSession();

    void start();
    void close();
    [[nodiscard]] bool open() const noexcept { return socket_.is_open(); }

  private:
    void read_more();
    void process();
    // Returns false when the connection must close after `out_` is written.
    bool handle_packet(const TcpPacket& packet);
    void send_and_continue(std::size_t size, bool close_after);

    asio::ip::tcp::socket socket_;
    Dispatcher& dispatcher_;
    TcpNodeTable& nodes_;
    std::uint8_t client_node_ = 0;  // 0 until the handshake succeeded
    // Room for two maximal packets so a read never has to wait for the parser.
    std::array<std::uint8_t, 2 * tcp_max_packet> in_{};
    std::size_t in_size_ = 0;
    std::array<std::uint8_t, tcp_max_packet> out_{};
    std::size_t out_size_pending_ = 0;  // bytes of out_ to send after handle_packet
};

}  // namespace fins::server
