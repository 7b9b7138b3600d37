// fins_soak's wire helpers: blocking loopback sockets with timeouts (every wait is
// bounded), FINS frames and FINS/TCP packets built with the codec, and the filter that
// keeps garbage from changing what the verifying clients own.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "fins/command_table.hpp"
#include "fins/frame.hpp"
#include "fins/tcp.hpp"

namespace fins::soak {

// An owned socket descriptor.
class Fd {
  public:
    Fd() = default;
    explicit Fd(int fd) : fd_(fd) {}
    Fd(Fd&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
    Fd& operator=(Fd&& o) noexcept {
        if (this != &o) {
            reset();
            fd_ = o.fd_;
            o.fd_ = -1;
        }
        return *this;
    }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    ~Fd() { reset(); }
    [[nodiscard]] int get() const { return fd_; }
    [[nodiscard]] bool valid() const { return fd_ >= 0; }
    void reset() {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
    }
    // Closes with SO_LINGER 0: the peer gets a reset instead of a FIN.
    void abort() {
        if (fd_ < 0) return;
        linger l{1, 0};
        ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &l, sizeof l);
        reset();
    }

  private:
    int fd_ = -1;
};

inline sockaddr_in loopback(std::uint16_t port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(port);
    return a;
}

inline void set_timeouts(int fd, int milliseconds) {
    timeval tv{milliseconds / 1000, (milliseconds % 1000) * 1000};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
}

// A UDP socket on 127.0.0.1 connected to finsd, so only finsd's datagrams arrive.
inline Fd udp_socket(std::uint16_t port, int timeout_ms) {
    Fd fd{::socket(AF_INET, SOCK_DGRAM, 0)};
    auto to = loopback(port);
    if (!fd.valid() || ::connect(fd.get(), reinterpret_cast<sockaddr*>(&to), sizeof to) != 0)
        return {};
    set_timeouts(fd.get(), timeout_ms);
    return fd;
}

inline Fd tcp_connect(std::uint16_t port, int timeout_ms) {
    Fd fd{::socket(AF_INET, SOCK_STREAM, 0)};
    if (!fd.valid()) return {};
    set_timeouts(fd.get(), timeout_ms);
    int one = 1;
    ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    auto to = loopback(port);
    if (::connect(fd.get(), reinterpret_cast<sockaddr*>(&to), sizeof to) != 0) return {};
    return fd;
}

inline bool send_all(int fd, const std::vector<std::uint8_t>& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::send(fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
        if (n <= 0) return false;
        done += static_cast<std::size_t>(n);
    }
    return true;
}

enum class Read { ok, eof, timeout, error };

inline Read recv_exact(int fd, std::uint8_t* p, std::size_t n) {
    while (n > 0) {
        const ssize_t r = ::recv(fd, p, n, 0);
        if (r == 0) return Read::eof;
        if (r < 0) return (errno == EAGAIN || errno == EWOULDBLOCK) ? Read::timeout : Read::error;
        p += r;
        n -= static_cast<std::size_t>(r);
    }
    return Read::ok;
}

inline std::uint32_t be32(const std::uint8_t* p) {
    return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
           p[3];
}

// One FINS/TCP packet (header + data). A header with a bad magic or length is returned
// alone with status ok: the caller judges it.
struct TcpReceived {
    Read status = Read::error;
    std::vector<std::uint8_t> packet;
    [[nodiscard]] bool well_formed() const {
        return status == Read::ok && packet.size() >= tcp_header_size &&
               be32(packet.data()) == tcp_magic && be32(packet.data() + 4) >= 8 &&
               be32(packet.data() + 4) <= tcp_max_length;
    }
    [[nodiscard]] std::uint32_t command() const { return be32(packet.data() + 8); }
    [[nodiscard]] std::uint32_t error() const { return be32(packet.data() + 12); }
};

inline TcpReceived receive_tcp_packet(int fd) {
    TcpReceived r;
    r.packet.resize(tcp_header_size);
    r.status = recv_exact(fd, r.packet.data(), tcp_header_size);
    if (r.status != Read::ok || !r.well_formed()) return r;
    const std::size_t rest = be32(r.packet.data() + 4) - 8;
    r.packet.resize(tcp_header_size + rest);
    r.status = recv_exact(fd, r.packet.data() + tcp_header_size, rest);
    return r;
}

inline std::vector<std::uint8_t> tcp_packet(TcpCommand command,
                                            const std::vector<std::uint8_t>& data,
                                            std::size_t declared) {
    std::vector<std::uint8_t> out(tcp_header_size + data.size());
    ByteWriter w{out};
    write_tcp_header(w, command, declared);
    w.bytes(data);
    return out;
}

inline std::vector<std::uint8_t> tcp_packet(TcpCommand command,
                                            const std::vector<std::uint8_t>& data) {
    return tcp_packet(command, data, data.size());
}

inline std::vector<std::uint8_t> handshake_request(std::uint8_t node) {
    std::vector<std::uint8_t> out(tcp_header_size + 4);
    ByteWriter w{out};
    write_node_address_request(w, node);
    return out;
}

inline std::vector<std::uint8_t> request(std::uint8_t destination_node, std::uint8_t source_node,
                                         std::uint8_t sid, CommandCode code,
                                         const std::vector<std::uint8_t>& params) {
    Header h;
    h.destination = {0, destination_node, 0};
    h.source = {0, source_node, 0};
    h.service_id = sid;
    std::vector<std::uint8_t> out(max_frame_size);
    const auto n = encode_request(h, code, params, out);
    out.resize(n.value_or(0));
    return out;
}

// Commands that change nothing another client could observe: reads, plus codes the
// command table does not know (answered 0401). Garbage is made of these only, so it can
// never write into a verifying client's words, take the access right or stop the CPU.
inline constexpr std::array<CommandCode, 10> harmless_commands{{{0x01, 0x01},
                                                                {0x01, 0x04},
                                                                {0x02, 0x01},
                                                                {0x03, 0x06},
                                                                {0x05, 0x01},
                                                                {0x05, 0x02},
                                                                {0x06, 0x01},
                                                                {0x07, 0x01},
                                                                {0x21, 0x02},
                                                                {0x21, 0x40}}};

inline bool harmless(CommandCode code) {
    if (find_command(code) == nullptr) return true;
    for (const auto& c : harmless_commands)
        if (c == code) return true;
    return false;
}

// Rewrites the command code of anything the server would take for a request into a
// harmless one (`pick` chooses which).
inline void defuse(std::vector<std::uint8_t>& frame, std::size_t pick) {
    if (frame.size() < header_size + command_code_size || (frame[0] & icf_response) != 0) return;
    if (harmless({frame[10], frame[11]})) return;
    const auto& c = harmless_commands[pick % harmless_commands.size()];
    frame[10] = c.main;
    frame[11] = c.sub;
}

}  // namespace fins::soak
