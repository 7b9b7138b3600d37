// The FINS/UDP peers a node heard from lately, for finsd's page and /api/status: a fixed
// table of the last `capacity` source addresses with the FINS node (SA1) their last
// datagram named and when it came. Noting a datagram allocates nothing: a look at the
// entry hit last, else a scan of the table, else the oldest entry is replaced.
#pragma once

#include "transport/socket_headers.hpp"

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace fins::server {

class RecentPeers {
  public:
    static constexpr std::size_t capacity = 16;
    struct Peer {
        sockaddr_storage address{};
        std::uint8_t node = 0;  // SA1 of its last datagram
        std::chrono::system_clock::time_point last_seen{};
        bool used = false;
    };

    void note(const sockaddr_storage& from, std::uint8_t node,
              std::chrono::system_clock::time_point now) noexcept {
        Peer* slot = same(peers_[last_], from) ? &peers_[last_] : nullptr;
        for (std::size_t i = 0; slot == nullptr && i < capacity; ++i)
            if (same(peers_[i], from)) {
                slot = &peers_[i];
                last_ = i;
            }
        if (slot == nullptr) {  // a new peer takes a free entry or the oldest
            std::size_t oldest = 0;
            for (std::size_t i = 0; i < capacity; ++i) {
                if (!peers_[i].used) {
                    oldest = i;
                    break;
                }
                if (peers_[i].last_seen < peers_[oldest].last_seen) oldest = i;
            }
            slot = &peers_[oldest];
            last_ = oldest;
            slot->address = from;
            slot->used = true;
        }
        slot->node = node;
        slot->last_seen = now;
    }
    [[nodiscard]] const std::array<Peer, capacity>& peers() const noexcept { return peers_; }

  private:
    static bool same(const Peer& p, const sockaddr_storage& a) noexcept {
        if (!p.used || p.address.ss_family != a.ss_family) return false;
        if (a.ss_family == AF_INET) {
            const auto& x = reinterpret_cast<const sockaddr_in&>(p.address);
            const auto& y = reinterpret_cast<const sockaddr_in&>(a);
            return x.sin_port == y.sin_port && x.sin_addr.s_addr == y.sin_addr.s_addr;
        }
        if (a.ss_family == AF_INET6) {
            const auto& x = reinterpret_cast<const sockaddr_in6&>(p.address);
            const auto& y = reinterpret_cast<const sockaddr_in6&>(a);
            return x.sin6_port == y.sin6_port &&
                   std::memcmp(&x.sin6_addr, &y.sin6_addr, sizeof x.sin6_addr) == 0;
        }
        return false;
    }
    std::array<Peer, capacity> peers_{};
    std::size_t last_ = 0;
};

}  // namespace fins::server
