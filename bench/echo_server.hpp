// fins_load's raw echo servers and the socket helpers they share with the load
// generator (bench/load.cpp): blocking sockets, one thread each. Header-only, bench only.
#pragma once

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <pthread.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <ctime>
#include <thread>
#include <vector>

namespace fins_bench {

inline void set_nodelay(int fd) {
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

inline void set_quickack(int fd) {
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_QUICKACK, &one, sizeof one);
}

// CPU time (user + system) a thread has used so far: what a server pays per request,
// which contention from other processes on the machine hardly changes.
inline double cpu_seconds(std::thread& thread) {
    clockid_t clock{};
    timespec ts{};
    if (pthread_getcpuclockid(thread.native_handle(), &clock) != 0 ||
        clock_gettime(clock, &ts) != 0)
        return 0;
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

inline bool read_exact(int fd, std::uint8_t* p, std::size_t n, bool quickack = false) {
    while (n > 0) {
        const ssize_t r = ::recv(fd, p, n, 0);
        if (r <= 0) return false;
        p += r;
        n -= static_cast<std::size_t>(r);
        if (quickack && n > 0) set_quickack(fd);  // the client waits for this ACK
    }
    return true;
}

// Raw echo servers: answer each request with a canned reply of the size finsd sends, on
// blocking sockets in a thread of their own. UDP: recvmmsg (blocking until at least one
// datagram, then whatever else is queued, up to 32) and one sendmmsg for the replies:
// the fewest system calls per datagram a server can make, so the ratio is finsd's cost
// over the kernel's own datagram path (`per_datagram`: one recvfrom and one sendto per
// datagram, the simplest echo). TCP: reads one request, writes one reply (TCP_NODELAY);
// with `quickack` it re-arms TCP_QUICKACK after a read that ends inside a request, as
// finsd does, so split-write clients are not held up by its delayed ACKs.
class EchoServer {
  public:
    struct Style {
        bool udp_batched = true;  // false: per datagram
        bool quickack = false;
    };
    EchoServer(bool tcp, std::size_t request_size, std::size_t response_size, Style style)
        : tcp_(tcp), style_(style), request_size_(request_size), response_(response_size, 0xC0) {
        fd_ = ::socket(AF_INET, tcp ? SOCK_STREAM : SOCK_DGRAM, 0);
        int one = 1;
        setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
        socklen_t len = sizeof a;
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
        port_ = ntohs(a.sin_port);
        if (tcp) ::listen(fd_, 4);
        thread_ = std::thread([this] {
            if (tcp_)
                serve_tcp();
            else if (style_.udp_batched)
                serve_udp();
            else
                serve_udp_per_datagram();
        });
    }
    ~EchoServer() {
        stop_ = true;
        ::shutdown(fd_, SHUT_RDWR);
        if (conn_ >= 0) ::shutdown(conn_, SHUT_RDWR);
        ::close(fd_);
        thread_.join();
        if (conn_ >= 0) ::close(conn_);
    }
    [[nodiscard]] std::uint16_t port() const { return port_; }
    double cpu() { return cpu_seconds(thread_); }

  private:
    void serve_udp() {
        constexpr unsigned batch = 32;
        std::vector<std::array<std::uint8_t, 2048>> bufs(batch);
        std::array<sockaddr_storage, batch> peers{};
        std::array<iovec, batch> in_iov{};
        std::array<mmsghdr, batch> in{};
        std::array<mmsghdr, batch> out{};
        iovec reply{response_.data(), response_.size()};
        for (unsigned i = 0; i < batch; ++i) {
            in_iov[i] = {bufs[i].data(), bufs[i].size()};
            in[i].msg_hdr.msg_iov = &in_iov[i];
            in[i].msg_hdr.msg_iovlen = 1;
            in[i].msg_hdr.msg_name = &peers[i];
            out[i].msg_hdr.msg_iov = &reply;
            out[i].msg_hdr.msg_iovlen = 1;
            out[i].msg_hdr.msg_name = &peers[i];
        }
        while (!stop_) {
            for (auto& m : in)
                m.msg_hdr.msg_namelen = sizeof(sockaddr_storage);
            const int n = ::recvmmsg(fd_, in.data(), batch, MSG_WAITFORONE, nullptr);
            if (n <= 0) return;
            for (int i = 0; i < n; ++i)
                out[static_cast<unsigned>(i)].msg_hdr.msg_namelen =
                    in[static_cast<unsigned>(i)].msg_hdr.msg_namelen;
            ::sendmmsg(fd_, out.data(), static_cast<unsigned>(n), 0);
        }
    }
    void serve_udp_per_datagram() {
        std::array<std::uint8_t, 4096> buf{};
        while (!stop_) {
            sockaddr_storage peer{};
            socklen_t len = sizeof peer;
            const ssize_t r = ::recvfrom(fd_, buf.data(), buf.size(), 0,
                                         reinterpret_cast<sockaddr*>(&peer), &len);
            if (r <= 0) return;
            ::sendto(fd_, response_.data(), response_.size(), 0, reinterpret_cast<sockaddr*>(&peer),
                     len);
        }
    }
    void serve_tcp() {
        conn_ = ::accept(fd_, nullptr, nullptr);
        if (conn_ < 0) return;
        set_nodelay(conn_);
        std::array<std::uint8_t, 4096> buf{};
        while (!stop_ && read_exact(conn_, buf.data(), request_size_, style_.quickack))
            if (::send(conn_, response_.data(), response_.size(), MSG_NOSIGNAL) <= 0) return;
    }

    bool tcp_;
    Style style_;
    std::size_t request_size_;
    std::vector<std::uint8_t> response_;
    int fd_ = -1;
    int conn_ = -1;
    std::uint16_t port_ = 0;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

}  // namespace fins_bench
