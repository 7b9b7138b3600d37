// Limits of finsd's FINS/TCP side (ServerOptions::tcp_limits, finsd [network] keys):
// deadlines, idle timeout, keep-alive and the cap on connections still in the
// handshake. docs/finsd.md "FINS/TCP identity and limits" gives the defaults and why.
#pragma once

#include <chrono>
#include <cstddef>

namespace fins::server {

struct TcpLimits {
    // From accept to a successful handshake.
    std::chrono::milliseconds handshake_timeout{10'000};
    // From the first byte of a packet to its last, and for a response to be written.
    std::chrono::milliseconds frame_timeout{10'000};
    // An established connection with no complete packet for this long is closed; 0 = never.
    std::chrono::milliseconds idle_timeout{300'000};
    // TCP keep-alive: first probe after this much silence, then 3 probes a third of it
    // apart (at least 1 s); 0 = off.
    std::chrono::seconds keepalive{60};
    // Connections accepted but not (yet) established, including those closing after an
    // error notice; accepting one more closes the oldest of them.
    std::size_t max_pending = 16;
    // How long a refused connection is drained before it is closed anyway.
    std::chrono::milliseconds drain_timeout{2'000};
};

}  // namespace fins::server
