#include "server/sessions/udp_batch.hpp"

#ifndef _WIN32
#include <netinet/in.h>
#include <sys/uio.h>
#endif

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>

#include <spdlog/spdlog.h>

namespace fins::server::udp_batch {

namespace {

// The reply's address length: an IPv4 peer's is that of sockaddr_in.
socklen_t reply_size(const Batch& b, std::size_t peer) noexcept {
    return b.peer[peer].ss_family == AF_INET ? static_cast<socklen_t>(sizeof(sockaddr_in))
                                             : b.peer_size[peer];
}

}  // namespace

#ifdef _WIN32

struct SystemHeaders {};

Batch::Batch() = default;
Batch::~Batch() = default;

void prepare(transport::os::NativeSocket s) noexcept {
    transport::os::prepare_nonblocking(s);
    // Without this, an ICMP port unreachable for an earlier reply fails the next recvfrom.
    // SIO_UDP_CONNRESET is _WSAIOW(IOC_VENDOR, 12) (mstcpip.h of newer SDKs).
    constexpr DWORD udp_connreset = 0x9800000C;
    BOOL report = FALSE;
    DWORD returned = 0;
    ::WSAIoctl(s, udp_connreset, &report, sizeof report, nullptr, 0, &returned, nullptr, nullptr);
}

std::size_t receive(transport::os::NativeSocket s, Batch& b) noexcept {
    std::size_t n = 0;
    // Bounded: at most batch_size datagrams, and a few errors, per call.
    for (std::size_t tries = 0; n < batch_size && tries < 2 * batch_size; ++tries) {
        int from_size = sizeof(sockaddr_storage);
        const int got =
            ::recvfrom(s, reinterpret_cast<char*>(b.in[n].data()), static_cast<int>(receive_size),
                       0, reinterpret_cast<sockaddr*>(&b.peer[n]), &from_size);
        if (got == SOCKET_ERROR) {
            const int error = ::WSAGetLastError();
            if (error == WSAEWOULDBLOCK) break;
            // A longer datagram: Winsock fills the buffer and says so; it is still more
            // than a frame, as on Linux.
            if (error != WSAEMSGSIZE) {
                if (error != WSAECONNRESET && error != WSAEINTR)
                    spdlog::debug("fins/udp: receive: error {}", error);
                continue;
            }
            b.in_size[n] = receive_size;
        } else {
            b.in_size[n] = static_cast<std::size_t>(got);
        }
        b.peer_size[n] = from_size;
        ++n;
    }
    return n;
}

Sent send(transport::os::NativeSocket s, Batch& b, std::size_t count) noexcept {
    Sent r;
    for (std::size_t i = 0; i < count; ++i) {
        const auto p = b.out_peer[i];
        switch (send_one(s, b.out[i].data(), b.out_size[i],
                         reinterpret_cast<const sockaddr*>(&b.peer[p]), reply_size(b, p))) {
            case SendOne::sent:
                ++r.sent;
                break;
            case SendOne::failed:
                ++r.failed;
                break;
            case SendOne::full:
                r.dropped = count - i;
                return r;
        }
    }
    return r;
}

SendOne send_one(transport::os::NativeSocket s, const std::uint8_t* data, std::size_t size,
                 const sockaddr* to, socklen_t to_size) noexcept {
    for (int attempt = 0; attempt < 4; ++attempt) {
        if (::sendto(s, reinterpret_cast<const char*>(data), static_cast<int>(size), 0, to,
                     to_size) != SOCKET_ERROR)
            return SendOne::sent;
        const int error = ::WSAGetLastError();
        if (error == WSAEINTR) continue;
        if (error == WSAEWOULDBLOCK || error == WSAENOBUFS) return SendOne::full;
        spdlog::debug("fins/udp: datagram not sent: error {}", error);
        return SendOne::failed;
    }
    return SendOne::failed;
}

#else

// recvmmsg/sendmmsg take arrays of message headers that point at the buffers; they are
// wired once here and only the lengths and reply addresses change per batch.
//
// A socket bound to a wildcard address (0.0.0.0, ::) gets each datagram's own destination
// address with it (IP_PKTINFO, IPV6_PKTINFO), and the reply leaves from that address: a
// request sent to 127.0.0.3 is answered from 127.0.0.3, not from the address the route
// would pick (127.0.0.1), which a connected client socket would drop, as it would on a host
// with several addresses. A PLC has one address, so it never answers from another.
constexpr std::size_t control_size = CMSG_SPACE(sizeof(in6_pktinfo));
static_assert(CMSG_SPACE(sizeof(in_pktinfo)) <= control_size);

struct SystemHeaders {
    std::array<iovec, batch_size> in_iov{};
    std::array<iovec, batch_size> out_iov{};
    std::array<mmsghdr, batch_size> in_msgs{};
    std::array<mmsghdr, batch_size> out_msgs{};
    // Received with each datagram, and the same bytes put on its reply (alignas: cmsghdr).
    alignas(cmsghdr) std::array<std::array<std::uint8_t, control_size>, batch_size> in_control{};
    alignas(cmsghdr) std::array<std::array<std::uint8_t, control_size>, batch_size> out_control{};
    std::array<std::size_t, batch_size> in_control_size{};
};

Batch::Batch() : headers(std::make_unique<SystemHeaders>()) {
    for (std::size_t i = 0; i < batch_size; ++i) {
        headers->in_iov[i] = {in[i].data(), in[i].size()};
        headers->in_msgs[i].msg_hdr.msg_name = &peer[i];
        headers->in_msgs[i].msg_hdr.msg_iov = &headers->in_iov[i];
        headers->in_msgs[i].msg_hdr.msg_iovlen = 1;
        headers->out_iov[i] = {out[i].data(), 0};
        headers->out_msgs[i].msg_hdr.msg_iov = &headers->out_iov[i];
        headers->out_msgs[i].msg_hdr.msg_iovlen = 1;
    }
}

namespace {

// The destination address of a received datagram as the control message a reply carries
// to leave from it (interface 0 unless IPv6 needs it for a link-local address): its
// length, 0 when the datagram came without one.
// One control message of `level`/`type` carrying `value`, written at `out`: its length.
template <typename T>
std::size_t put_control(std::uint8_t* out, int level, int type, const T& value) noexcept {
    auto* c = reinterpret_cast<cmsghdr*>(out);
    c->cmsg_level = level;
    c->cmsg_type = type;
    c->cmsg_len = CMSG_LEN(sizeof value);
    std::memcpy(CMSG_DATA(c), &value, sizeof value);
    return CMSG_SPACE(sizeof value);
}

std::size_t reply_control(const msghdr& received, std::uint8_t* out) noexcept {
    for (cmsghdr* c = CMSG_FIRSTHDR(&received); c != nullptr;
         c = CMSG_NXTHDR(const_cast<msghdr*>(&received), c)) {
        if (c->cmsg_level == IPPROTO_IP && c->cmsg_type == IP_PKTINFO) {
            in_pktinfo got{};
            std::memcpy(&got, CMSG_DATA(c), sizeof got);
            // ipi_spec_dst: the datagram's destination, or for a broadcast the
            // interface's own address (never 255.255.255.255).
            in_pktinfo reply{};
            reply.ipi_spec_dst = got.ipi_spec_dst;
            return put_control(out, IPPROTO_IP, IP_PKTINFO, reply);
        }
        if (c->cmsg_level == IPPROTO_IPV6 && c->cmsg_type == IPV6_PKTINFO) {
            in6_pktinfo reply{};
            std::memcpy(&reply, CMSG_DATA(c), sizeof reply);
            if (IN6_IS_ADDR_MULTICAST(&reply.ipi6_addr)) return 0;  // the route's choice
            if (!IN6_IS_ADDR_LINKLOCAL(&reply.ipi6_addr)) reply.ipi6_ifindex = 0;
            return put_control(out, IPPROTO_IPV6, IPV6_PKTINFO, reply);
        }
    }
    return 0;
}

bool is_wildcard(const sockaddr_storage& a) noexcept {
    if (a.ss_family == AF_INET)
        return reinterpret_cast<const sockaddr_in&>(a).sin_addr.s_addr == htonl(INADDR_ANY);
    if (a.ss_family == AF_INET6)
        return IN6_IS_ADDR_UNSPECIFIED(&reinterpret_cast<const sockaddr_in6&>(a).sin6_addr);
    return false;
}

}  // namespace

Batch::~Batch() = default;

// MSG_DONTWAIT on every call; the destination address of each datagram on a wildcard
// socket (a dual-stack IPv6 socket reports IPv4 datagrams' with IP_PKTINFO).
void prepare(transport::os::NativeSocket s) noexcept {
    sockaddr_storage local{};
    socklen_t size = sizeof local;
    if (::getsockname(s, reinterpret_cast<sockaddr*>(&local), &size) != 0 || !is_wildcard(local))
        return;
    const int on = 1;
    if (local.ss_family == AF_INET6 &&
        ::setsockopt(s, IPPROTO_IPV6, IPV6_RECVPKTINFO, &on, sizeof on) != 0)
        spdlog::debug("fins/udp: IPV6_RECVPKTINFO: {}", std::strerror(errno));
    // Also on an IPv6 socket: its IPv4-mapped peers' datagrams (fails harmlessly if v6 only).
    if (::setsockopt(s, IPPROTO_IP, IP_PKTINFO, &on, sizeof on) != 0 && local.ss_family == AF_INET)
        spdlog::debug("fins/udp: IP_PKTINFO: {}", std::strerror(errno));
}

namespace {

bool would_block(int error) noexcept {
    return error == EAGAIN || error == EWOULDBLOCK;
}

}  // namespace

std::size_t receive(transport::os::NativeSocket s, Batch& b) noexcept {
    SystemHeaders& h = *b.headers;
    for (std::size_t i = 0; i < batch_size; ++i) {
        h.in_msgs[i].msg_hdr.msg_namelen = sizeof(sockaddr_storage);
        h.in_msgs[i].msg_hdr.msg_control = h.in_control[i].data();
        h.in_msgs[i].msg_hdr.msg_controllen = control_size;
    }
    const int received = ::recvmmsg(s, h.in_msgs.data(), batch_size, MSG_DONTWAIT, nullptr);
    if (received <= 0) {
        // EAGAIN: drained. Anything else (an error queued on the socket, which reading
        // clears): log it; the session waits for readiness again.
        if (received < 0 && !would_block(errno) && errno != EINTR)
            spdlog::debug("fins/udp: receive: {}", std::strerror(errno));
        return 0;
    }
    const auto n = static_cast<std::size_t>(received);
    for (std::size_t i = 0; i < n; ++i) {
        // A longer datagram was cut to receive_size (MSG_TRUNC), still more than a frame.
        b.in_size[i] = std::min<std::size_t>(h.in_msgs[i].msg_len, receive_size);
        b.peer_size[i] = h.in_msgs[i].msg_hdr.msg_namelen;
        h.in_control_size[i] = reply_control(h.in_msgs[i].msg_hdr, h.out_control[i].data());
    }
    return n;
}

Sent send(transport::os::NativeSocket s, Batch& b, std::size_t count) noexcept {
    SystemHeaders& h = *b.headers;
    for (std::size_t i = 0; i < count; ++i) {
        h.out_iov[i].iov_len = b.out_size[i];
        h.out_msgs[i].msg_hdr.msg_name = &b.peer[b.out_peer[i]];
        h.out_msgs[i].msg_hdr.msg_namelen = reply_size(b, b.out_peer[i]);
        // The reply control bytes were built at receive time, by the peer's index.
        const std::size_t control = h.in_control_size[b.out_peer[i]];
        h.out_msgs[i].msg_hdr.msg_control = control ? h.out_control[b.out_peer[i]].data() : nullptr;
        h.out_msgs[i].msg_hdr.msg_controllen = control;
    }
    Sent r;
    std::size_t done = 0;
    // Each pass sends at least one reply or gives up on one; EINTR retries are bounded.
    for (std::size_t attempt = 0; done < count && attempt < 2 * batch_size; ++attempt) {
        const int sent = ::sendmmsg(s, &h.out_msgs[done], static_cast<unsigned>(count - done),
                                    MSG_DONTWAIT | MSG_NOSIGNAL);
        if (sent > 0) {
            done += static_cast<std::size_t>(sent);
            r.sent += static_cast<std::size_t>(sent);
            continue;
        }
        const int error = errno;
        if (error == EINTR) continue;
        if (would_block(error) || error == ENOBUFS) break;  // the send buffer is full
        // This one reply cannot go out (e.g. a source address one cannot send to): skip it.
        spdlog::debug("fins/udp: reply dropped: {}", std::strerror(error));
        ++r.failed;
        ++done;
    }
    r.dropped = count - done;
    return r;
}

SendOne send_one(transport::os::NativeSocket s, const std::uint8_t* data, std::size_t size,
                 const sockaddr* to, socklen_t to_size) noexcept {
    for (int attempt = 0; attempt < 4; ++attempt) {
        if (::sendto(s, data, size, MSG_DONTWAIT | MSG_NOSIGNAL, to, to_size) >= 0)
            return SendOne::sent;
        if (errno == EINTR) continue;
        if (would_block(errno) || errno == ENOBUFS) return SendOne::full;
        spdlog::debug("fins/udp: datagram not sent: {}", std::strerror(errno));
        return SendOne::failed;
    }
    return SendOne::failed;
}

#endif

}  // namespace fins::server::udp_batch
