#pragma once
// The few socket calls Asio has no portable form for, on Linux and on Windows
// (docs/windows.md): TCP keep-alive timing, a peek that tells a closed peer, and
// clearing a pending socket error. Everything else goes through Asio.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include <boost/system/error_code.hpp>

namespace fins::transport::os {

// What an Asio socket's native_handle() gives (or converts to): SOCKET on Windows.
#ifdef _WIN32
using NativeSocket = std::uintptr_t;
#else
using NativeSocket = int;
#endif
inline constexpr NativeSocket invalid_socket = static_cast<NativeSocket>(-1);

struct KeepAliveTiming {
    std::chrono::seconds idle{0};      // silence before the first probe
    std::chrono::seconds interval{1};  // between probes
    int probes = 3;                    // unanswered probes before the connection is dead
    // Linux only (TCP_USER_TIMEOUT): unacknowledged data older than this ends the
    // connection; 0 leaves the system's rule. Windows' counterpart is TCP_MAXRT (seconds).
    std::chrono::milliseconds user_timeout{0};
};

// Turns keep-alive on with this timing. Windows sets idle and interval
// (SIO_KEEPALIVE_VALS); its probe count is the system's (10), not `probes`.
boost::system::error_code set_keepalive(NativeSocket s, const KeepAliveTiming& timing) noexcept;

// Reads and drops the socket's pending error (SO_ERROR), e.g. an ICMP port unreachable
// left by earlier traffic.
void clear_pending_error(NativeSocket s) noexcept;

enum class Peek { closed, data, nothing, failed };
// Looks at the stream without consuming or blocking: closed (orderly end), data waiting,
// nothing yet, or failed (reset and other errors).
Peek peek(NativeSocket s) noexcept;

// Puts the socket in non-blocking mode for receive_now/send_now on Windows; Linux passes
// MSG_DONTWAIT on each call instead (nothing to do).
void prepare_nonblocking(NativeSocket s) noexcept;

// A read or write that never waits.
struct Moved {
    enum class Kind { done, would_block, interrupted, failed } kind = Kind::done;
    std::size_t bytes = 0;  // when done (a read of 0: the peer closed its side)
    int error = 0;          // when failed: errno, or the WSA error on Windows
};
Moved receive_now(NativeSocket s, std::uint8_t* into, std::size_t size) noexcept;
// Never raises SIGPIPE on a closed peer (MSG_NOSIGNAL).
Moved send_now(NativeSocket s, const std::uint8_t* data, std::size_t size) noexcept;
// The text of a Moved::error.
std::string error_text(int error);

}  // namespace fins::transport::os
