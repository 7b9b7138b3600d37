// fins_load's request generator, also fins_web_load's FINS side: the 1-word MEMORY AREA
// READ of D0 as a FINS frame, a blocking loopback socket, and the loop that keeps `depth`
// requests in flight and times each. Header-only, bench only.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "echo_server.hpp"
#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "fins/tcp.hpp"

namespace fins_bench {

using Clock = std::chrono::steady_clock;

struct Frames {
    std::vector<std::uint8_t> request;  // what the generator sends (with envelope on TCP)
    std::size_t response_size = 0;      // what comes back
};

// finsd's answer to read_frame(): header, command code, end code, one word.
inline constexpr std::size_t read_response_size = fins::header_size + 2 + 2 + 2;

// The 1-word read of D0 from node 200 as a FINS frame.
inline std::vector<std::uint8_t> read_frame(std::uint8_t sid) {
    std::array<std::uint8_t, 32> params{};
    fins::ByteWriter pw{params};
    fins::MemoryAreaRead{{0x82, 0, 0}, 1}.encode(pw);
    fins::Header h;
    h.destination = {0, 1, 0};
    h.source = {0, 200, 0};
    h.service_id = sid;
    std::vector<std::uint8_t> out(fins::max_frame_size);
    auto n = fins::encode_request(h, fins::MemoryAreaRead::code, pw.written(), out);
    out.resize(n.value_or(0));
    return out;
}

// What the generator sends and gets back for read_frame(sid): with the FINS/TCP header
// on TCP.
inline Frames read_frames(bool tcp, std::uint8_t sid = 1) {
    Frames f{read_frame(sid), read_response_size};
    if (tcp) {
        std::array<std::uint8_t, 16> envelope{};
        fins::ByteWriter w{envelope};
        fins::write_tcp_header(w, fins::TcpCommand::frame, f.request.size());
        f.request.insert(f.request.begin(), envelope.begin(), envelope.end());
        f.response_size += fins::tcp_header_size;
    }
    return f;
}

// FINS/TCP handshake by hand: ask for node 200, the source node of read_frame() (finsd
// executes only frames from the node the connection got), read the 24-byte answer.
inline bool tcp_handshake(int fd) {
    std::array<std::uint8_t, 24> buf{};
    fins::ByteWriter w{buf};
    fins::write_node_address_request(w, 200);
    if (::send(fd, buf.data(), w.size(), MSG_NOSIGNAL) <= 0) return false;
    return read_exact(fd, buf.data(), 24);
}

struct Stats {
    double rate = 0;
    double p50_us = 0;
    double p99_us = 0;
    std::size_t count = 0;
    double cpu_us = 0;  // the server thread's CPU time over the case

    [[nodiscard]] double cpu_per_request_us() const {
        return count > 0 ? cpu_us / static_cast<double>(count) : 0;
    }
};

inline int connect_to(bool tcp, std::uint16_t port, bool nodelay = true) {
    const int fd = ::socket(AF_INET, tcp ? SOCK_STREAM : SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(port);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        ::close(fd);
        return -1;
    }
    if (tcp && nodelay) set_nodelay(fd);
    // A lost datagram must end the case, not hang it.
    timeval tv{1, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    return fd;
}

// The rate since `start` and the p50/p99 of `latencies` (sorted here).
inline Stats stats_of(std::vector<double>& latencies, Clock::time_point start) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    Stats s;
    s.count = latencies.size();
    if (latencies.empty()) return s;
    std::sort(latencies.begin(), latencies.end());
    s.rate = static_cast<double>(latencies.size()) / elapsed;
    s.p50_us = latencies[latencies.size() / 2];
    s.p99_us = latencies[std::min(latencies.size() - 1, latencies.size() * 99 / 100)];
    return s;
}

// Keeps `depth` requests outstanding for `seconds`; a request's latency is measured
// from its send to the arrival of the next response (responses come back in order).
// `split`: each request goes out in two writes, the FINS/TCP header, then the frame.
inline Stats drive(int fd, bool tcp, const Frames& f, unsigned depth, double seconds,
                   bool split = false) {
    std::vector<Clock::time_point> sent;
    sent.reserve(1 << 20);
    std::vector<double> latencies;
    latencies.reserve(1 << 20);
    std::vector<std::uint8_t> in(f.response_size + 64);
    const auto start = Clock::now();
    const auto end =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    std::size_t next_reply = 0;
    auto send_one = [&] {
        sent.push_back(Clock::now());
        if (split)
            return ::send(fd, f.request.data(), fins::tcp_header_size, MSG_NOSIGNAL) > 0 &&
                   ::send(fd, f.request.data() + fins::tcp_header_size,
                          f.request.size() - fins::tcp_header_size, MSG_NOSIGNAL) > 0;
        return ::send(fd, f.request.data(), f.request.size(), MSG_NOSIGNAL) > 0;
    };
    for (unsigned i = 0; i < depth; ++i)
        if (!send_one()) return {};
    bool sending = true;
    while (next_reply < sent.size()) {
        const bool ok = tcp ? read_exact(fd, in.data(), f.response_size)
                            : ::recv(fd, in.data(), in.size(), 0) > 0;
        if (!ok) break;
        const auto now = Clock::now();
        latencies.push_back(
            std::chrono::duration<double, std::micro>(now - sent[next_reply]).count());
        ++next_reply;
        if (sending && now < end) {
            if (!send_one()) break;
        } else {
            sending = false;
        }
    }
    return stats_of(latencies, start);
}

}  // namespace fins_bench

namespace fins_bench {

inline bool send_all(int fd, const std::uint8_t* p, std::size_t n) {
    while (n > 0) {
        const ssize_t w = ::send(fd, p, n, MSG_NOSIGNAL);
        if (w <= 0) return false;
        p += w;
        n -= static_cast<std::size_t>(w);
    }
    return true;
}

// drive() with the generator's system calls batched: every answer that has arrived is
// taken in one call (recvmmsg on UDP, one recv on TCP) and as many requests go out in one
// call (sendmmsg, one send). The generator then spends much less CPU per request than the
// server, as clients on other hosts would: on a 2-core host, what limits the rate is the
// server, not the generator. A latency is measured from the send of its batch to the
// arrival of the batch that answered it.
inline Stats drive_batched(int fd, bool tcp, const Frames& f, unsigned depth, double seconds) {
    const std::size_t request = f.request.size(), response = f.response_size;
    std::vector<std::uint8_t> requests;  // `depth` copies of the request, back to back
    for (unsigned i = 0; i < depth; ++i)
        requests.insert(requests.end(), f.request.begin(), f.request.end());
    std::vector<std::uint8_t> in(response * depth + 64 * depth);
    std::vector<mmsghdr> out_msgs(depth), in_msgs(depth);
    std::vector<iovec> out_iov(depth), in_iov(depth);
    for (unsigned i = 0; i < depth; ++i) {
        out_iov[i] = {requests.data() + i * request, request};
        out_msgs[i].msg_hdr.msg_iov = &out_iov[i];
        out_msgs[i].msg_hdr.msg_iovlen = 1;
        in_iov[i] = {in.data() + i * (response + 64), response + 64};
        in_msgs[i].msg_hdr.msg_iov = &in_iov[i];
        in_msgs[i].msg_hdr.msg_iovlen = 1;
    }
    std::vector<Clock::time_point> sent;
    sent.reserve(1 << 20);
    std::vector<double> latencies;
    latencies.reserve(1 << 20);
    auto send_batch = [&](unsigned n) {
        const auto now = Clock::now();
        for (unsigned i = 0; i < n; ++i)
            sent.push_back(now);
        if (!tcp) return ::sendmmsg(fd, out_msgs.data(), n, 0) == static_cast<int>(n);
        return send_all(fd, requests.data(), n * request);
    };
    const auto start = Clock::now();
    const auto end =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    if (!send_batch(depth)) return {};
    std::size_t next_reply = 0, partial = 0;  // TCP: bytes of an answer not yet complete
    bool sending = true;
    while (next_reply < sent.size()) {
        unsigned got = 0;
        if (!tcp) {
            const int n = ::recvmmsg(fd, in_msgs.data(), depth, MSG_WAITFORONE, nullptr);
            if (n <= 0) break;
            got = static_cast<unsigned>(n);
        } else {
            const ssize_t n = ::recv(fd, in.data(), in.size(), 0);
            if (n <= 0) break;
            partial += static_cast<std::size_t>(n);
            got = static_cast<unsigned>(partial / response);
            partial %= response;
        }
        const auto now = Clock::now();
        for (unsigned i = 0; i < got && next_reply < sent.size(); ++i, ++next_reply)
            latencies.push_back(
                std::chrono::duration<double, std::micro>(now - sent[next_reply]).count());
        if (sending && now < end) {
            if (got > 0 && !send_batch(got)) break;
        } else {
            sending = false;
        }
    }
    return stats_of(latencies, start);
}

}  // namespace fins_bench
