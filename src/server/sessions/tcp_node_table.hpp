// The FINS/TCP connection table the sessions share (W421 7-4, frames-networks 3.3):
// which client node each established connection holds. The node a connection got in
// the handshake is its identity for as long as it is open.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "fins/error.hpp"
#include "server/sessions/tcp_session_log.hpp"

namespace fins::server {

class TcpSession;

class TcpNodeTable {
  public:
    TcpNodeTable(std::uint8_t server_node, std::size_t max_connections) noexcept
        : server_node_(server_node), max_connections_(max_connections) {}

    // Claims `requested` (0 = allocate one) for `owner`. Returns the node or the
    // envelope error of W421 7-4 command 1 (0x20, 0x21, 0x23, 0x24, 0x25).
    Result<std::uint8_t> claim(std::uint8_t requested, TcpSession* owner) noexcept;
    // Frees `node` if `owner` holds it (a stale release never frees a reused node).
    void release(std::uint8_t node, const TcpSession* owner) noexcept;
    // The session holding `node`, or nullptr.
    [[nodiscard]] TcpSession* owner(std::uint8_t node) const noexcept { return owners_[node]; }
    // Connections accepted from clients and holding a node.
    [[nodiscard]] std::size_t in_use() const noexcept { return count_; }
    // W596 1-4: the limit counts "server and client connections"; each configured
    // FINS/TCP client connection (tcp_client.hpp) holds one of the slots for good.
    void reserve_for_clients(std::size_t clients) noexcept { reserved_ = clients; }
    [[nodiscard]] std::size_t reserved() const noexcept { return reserved_; }
    [[nodiscard]] bool full() const noexcept { return count_ + reserved_ >= max_connections_; }
    // The server's FINS/TCP log lines, bounded per interval (tcp_session_log.hpp).
    TcpSessionLog& log() noexcept { return log_; }

  private:
    std::array<TcpSession*, 256> owners_{};
    std::uint8_t server_node_;
    std::size_t max_connections_;
    std::size_t count_ = 0;
    std::size_t reserved_ = 0;
    TcpSessionLog log_;
};

}  // namespace fins::server
