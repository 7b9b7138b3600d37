// fins_soak's clients, one thread each, all against one finsd on 127.0.0.1:
//   verifying UDP and TCP clients: each owns a range of DM words and mixes writes,
//     fills, reads and multiple reads, checking every answer (SID, addresses, command,
//     end code, length, data) against its own copy of its words;
//   garbage senders: random and mutated datagrams (never state-changing commands);
//   churners: connect/handshake/close, resets, half handshakes and malformed streams.
// Mismatches are fatal to the run; errors (UDP timeouts, refused churn) are counted.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

namespace fins::soak {

struct Stats {
    std::atomic<std::uint64_t> udp_verified{0};
    std::atomic<std::uint64_t> tcp_verified{0};
    std::atomic<std::uint64_t> mismatches{0};
    std::atomic<std::uint64_t> errors{0};
    std::atomic<std::uint64_t> garbage_datagrams{0};
    std::atomic<std::uint64_t> garbage_answers{0};
    std::atomic<std::uint64_t> connections{0};  // churned: opened and closed
    std::atomic<std::uint64_t> malformed_streams{0};
    std::atomic<std::uint64_t> resets{0};

    void mismatch(const std::string& what);
    void error(const std::string& what);

  private:
    void print(const char* kind, const std::string& what, std::uint64_t count);
    std::mutex print_mutex_;
};

struct Target {
    std::uint16_t port = 0;
    std::uint8_t server_node = 1;
};

// Words [first, first + count) of DM belong to one verifying client.
struct Range {
    std::uint16_t first = 0;
    std::uint16_t count = 0;
};

// Each runs until `stop` is set; every socket wait is bounded, so they return within
// a few seconds of it. `ready` is set once the client is connected (TCP: handshaken).
void run_udp_client(Target t, Range r, std::uint8_t node, std::uint64_t seed, Stats& stats,
                    const std::atomic<bool>& stop);
void run_tcp_client(Target t, Range r, std::uint64_t seed, Stats& stats, std::atomic<int>& ready,
                    const std::atomic<bool>& stop);
void run_garbage_sender(Target t, unsigned per_second, std::uint64_t seed, Stats& stats,
                        const std::atomic<bool>& stop);
void run_churner(Target t, unsigned per_second, std::uint64_t seed, Stats& stats,
                 const std::atomic<bool>& stop);

}  // namespace fins::soak
