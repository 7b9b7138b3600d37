#pragma once
// The system calls under UdpSession (udp_session.hpp): a batch of datagrams in, a batch
// of replies out, never waiting. Linux: one recvmmsg and one sendmmsg per batch. Windows
// (docs/windows.md): recvfrom and sendto per datagram on a non-blocking socket, with
// Winsock's report of an ICMP port unreachable on UDP (WSAECONNRESET) turned off.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fins/frame.hpp"
#include "transport/socket_headers.hpp"
#include "transport/socket_os.hpp"

namespace fins::server::udp_batch {

inline constexpr std::size_t batch_size = 32;
// A datagram one byte longer than the largest frame is still received long enough for
// the dispatcher to answer 1001 instead of seeing a silently truncated frame.
inline constexpr std::size_t receive_size = max_frame_size + 1;

struct SystemHeaders;  // recvmmsg/sendmmsg's message headers (Linux only)

// One thread's buffers (not zeroed: only received bytes and written replies are read).
struct Batch {
    Batch();
    ~Batch();
    Batch(const Batch&) = delete;
    Batch& operator=(const Batch&) = delete;

    std::array<std::array<std::uint8_t, receive_size>, batch_size> in;
    std::array<std::size_t, batch_size> in_size;  // bytes received (at most receive_size)
    std::array<sockaddr_storage, batch_size> peer;
    std::array<socklen_t, batch_size> peer_size;
    std::array<std::array<std::uint8_t, max_frame_size>, batch_size> out;
    std::array<std::size_t, batch_size> out_size;  // the reply's bytes
    std::array<std::size_t, batch_size> out_peer;  // the index of the peer it goes to
    std::unique_ptr<SystemHeaders> headers;        // none on Windows
};

// Prepares a bound socket for receive(): non-blocking; on Windows no WSAECONNRESET.
void prepare(transport::os::NativeSocket s) noexcept;

// Receives what is queued, up to batch_size datagrams, without waiting: how many
// (0: nothing was queued, or an error, which is logged at debug and cleared by reading).
std::size_t receive(transport::os::NativeSocket s, Batch& b) noexcept;

struct Sent {
    std::size_t sent = 0;
    std::size_t failed = 0;   // replies the system refused one by one (skipped)
    std::size_t dropped = 0;  // replies left when the send buffer was full
};
// Sends replies 0..count-1 (out, out_size, out_peer).
Sent send(transport::os::NativeSocket s, Batch& b, std::size_t count) noexcept;

enum class SendOne { sent, full, failed };
// One datagram to `to` without waiting.
SendOne send_one(transport::os::NativeSocket s, const std::uint8_t* data, std::size_t size,
                 const sockaddr* to, socklen_t to_size) noexcept;

}  // namespace fins::server::udp_batch
