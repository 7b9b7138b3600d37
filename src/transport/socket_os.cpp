#include "transport/socket_os.hpp"

#ifdef _WIN32
// Winsock's headers need their order: winsock2.h first.
#include <winsock2.h>

#include <ws2tcpip.h>

#include <mstcpip.h>
#else
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <cerrno>
#endif

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace fins::transport::os {

namespace {

boost::system::error_code last_error() noexcept {
#ifdef _WIN32
    return {::WSAGetLastError(), boost::system::system_category()};
#else
    return {errno, boost::system::system_category()};
#endif
}

int clamp_seconds(std::chrono::seconds s) noexcept {
    return static_cast<int>(std::clamp<std::chrono::seconds::rep>(s.count(), 1, 32767));
}

}  // namespace

boost::system::error_code set_keepalive(NativeSocket s, const KeepAliveTiming& timing) noexcept {
    const int on = 1;
    const int idle = clamp_seconds(timing.idle);
    const int interval = clamp_seconds(timing.interval);
#ifdef _WIN32
    if (::setsockopt(s, SOL_SOCKET, SO_KEEPALIVE, reinterpret_cast<const char*>(&on), sizeof on) !=
        0)
        return last_error();
    tcp_keepalive values{};
    values.onoff = 1;
    values.keepalivetime = static_cast<ULONG>(idle) * 1000;
    values.keepaliveinterval = static_cast<ULONG>(interval) * 1000;
    DWORD returned = 0;
    if (::WSAIoctl(s, SIO_KEEPALIVE_VALS, &values, sizeof values, nullptr, 0, &returned, nullptr,
                   nullptr) != 0)
        return last_error();
    if (timing.user_timeout.count() > 0) {
        // TCP_MAXRT (ws2ipdef.h of newer SDKs; not in MinGW-w64 10's headers): seconds.
        constexpr int tcp_maxrt = 5;
        const auto maxrt = static_cast<DWORD>(
            std::max<std::int64_t>(1, (timing.user_timeout.count() + 999) / 1000));
        if (::setsockopt(s, IPPROTO_TCP, tcp_maxrt, reinterpret_cast<const char*>(&maxrt),
                         sizeof maxrt) != 0)
            return last_error();
    }
#else
    const int probes = std::max(timing.probes, 1);
    if (::setsockopt(s, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof on) != 0 ||
        ::setsockopt(s, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle) != 0 ||
        ::setsockopt(s, IPPROTO_TCP, TCP_KEEPINTVL, &interval, sizeof interval) != 0 ||
        ::setsockopt(s, IPPROTO_TCP, TCP_KEEPCNT, &probes, sizeof probes) != 0)
        return last_error();
    if (timing.user_timeout.count() > 0) {
        const auto ms =
            static_cast<unsigned>(std::min<std::int64_t>(timing.user_timeout.count(), 0x7FFFFFFF));
        if (::setsockopt(s, IPPROTO_TCP, TCP_USER_TIMEOUT, &ms, sizeof ms) != 0)
            return last_error();
    }
#endif
    return {};
}

void clear_pending_error(NativeSocket s) noexcept {
    int error = 0;
#ifdef _WIN32
    int size = sizeof error;
    ::getsockopt(s, SOL_SOCKET, SO_ERROR, reinterpret_cast<char*>(&error), &size);
#else
    socklen_t size = sizeof error;
    ::getsockopt(s, SOL_SOCKET, SO_ERROR, &error, &size);
#endif
}

Peek peek(NativeSocket s) noexcept {
    char byte = 0;
#ifdef _WIN32
    // The socket is non-blocking (Asio's non_blocking(true), or its own reactor's mode).
    const int r = ::recv(s, &byte, 1, MSG_PEEK);
    if (r == 0) return Peek::closed;
    if (r > 0) return Peek::data;
    const int e = ::WSAGetLastError();
    return e == WSAEWOULDBLOCK || e == WSAEINTR ? Peek::nothing : Peek::failed;
#else
    const auto r = ::recv(s, &byte, 1, MSG_PEEK | MSG_DONTWAIT);
    if (r == 0) return Peek::closed;
    if (r > 0) return Peek::data;
    return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? Peek::nothing : Peek::failed;
#endif
}

#ifdef _WIN32

void prepare_nonblocking(NativeSocket s) noexcept {
    u_long on = 1;
    ::ioctlsocket(s, static_cast<long>(FIONBIO), &on);
}

namespace {

Moved moved(int n) noexcept {
    if (n != SOCKET_ERROR) return {Moved::Kind::done, static_cast<std::size_t>(n), 0};
    const int e = ::WSAGetLastError();
    if (e == WSAEWOULDBLOCK) return {Moved::Kind::would_block, 0, e};
    if (e == WSAEINTR) return {Moved::Kind::interrupted, 0, e};
    return {Moved::Kind::failed, 0, e};
}

int int_size(std::size_t size) noexcept {
    return static_cast<int>(std::min<std::size_t>(size, 0x7FFFFFFF));
}

}  // namespace

Moved receive_now(NativeSocket s, std::uint8_t* into, std::size_t size) noexcept {
    return moved(::recv(s, reinterpret_cast<char*>(into), int_size(size), 0));
}

Moved send_now(NativeSocket s, const std::uint8_t* data, std::size_t size) noexcept {
    return moved(::send(s, reinterpret_cast<const char*>(data), int_size(size), 0));
}

std::string error_text(int error) {
    return boost::system::error_code(error, boost::system::system_category()).message();
}

#else

void prepare_nonblocking(NativeSocket) noexcept {}

namespace {

Moved moved(ssize_t n) noexcept {
    if (n >= 0) return {Moved::Kind::done, static_cast<std::size_t>(n), 0};
    const int e = errno;
    if (e == EAGAIN || e == EWOULDBLOCK) return {Moved::Kind::would_block, 0, e};
    if (e == EINTR) return {Moved::Kind::interrupted, 0, e};
    return {Moved::Kind::failed, 0, e};
}

}  // namespace

Moved receive_now(NativeSocket s, std::uint8_t* into, std::size_t size) noexcept {
    return moved(::recv(s, into, size, MSG_DONTWAIT));
}

Moved send_now(NativeSocket s, const std::uint8_t* data, std::size_t size) noexcept {
    return moved(::send(s, data, size, MSG_DONTWAIT | MSG_NOSIGNAL));
}

std::string error_text(int error) {
    return std::strerror(error);
}

#endif

}  // namespace fins::transport::os
