// A FINS/TCP client by hand for session tests: handshake, then memory-area reads; every
// send and receive has a timeout, so a stuck server fails a test instead of hanging it.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "fins/byte_io.hpp"
#include "fins/tcp.hpp"
#include "server/frame_builder.hpp"
#include "server/sessions/server.hpp"

namespace fins::test {

// finsd on 127.0.0.1, an ephemeral port, FINS/UDP off: FINS/TCP is its only way in or out.
inline Result<std::unique_ptr<server::Server>> start_tcp_only(asio::io_context& io, plc::Plc& plc) {
    server::ServerOptions options;
    options.port = 0;
    options.udp = false;
    return server::Server::start(io, plc, options);
}

class TcpPeer {
  public:
    // `receive_buffer` > 0 sets SO_RCVBUF before connecting (a slow reader's small window).
    explicit TcpPeer(std::uint16_t port, int receive_buffer = 0) {
        fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
        timeval tv{5, 0};
        ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
        ::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
        if (receive_buffer > 0)
            ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        a.sin_port = htons(port);
        connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    }
    ~TcpPeer() { ::close(fd_); }
    TcpPeer(const TcpPeer&) = delete;
    TcpPeer& operator=(const TcpPeer&) = delete;

    bool handshake() {
        std::array<std::uint8_t, 24> buf{};
        ByteWriter w{buf};
        write_node_address_request(w, 0);
        if (!connected_ || !send_all(buf.data(), w.size()) || !receive(buf.data(), 24))
            return false;
        node_ = buf[19];  // the client node the server gave us (frames 3.4)
        return true;
    }
    // MEMORY AREA READ of `words` DM words from D0 in a FRAME SEND packet.
    [[nodiscard]] std::vector<std::uint8_t> read_packet(std::uint8_t sid,
                                                        std::uint16_t words = 1) const {
        FrameFields f;
        f.service_id = sid;
        f.destination = {0, 0, 0};
        f.source = {0, node_, 0};
        const auto frame = request_frame(fmt::format("0101 82000000 {:04X}", words), f);
        std::vector<std::uint8_t> packet(tcp_header_size + frame.size());
        ByteWriter w{packet};
        write_tcp_header(w, TcpCommand::frame, frame.size());
        w.bytes(frame);
        return packet;
    }
    // Sends one 1-word read, returns the end code (0xFFFF: no answer, 0xFFFE: wrong SID).
    std::uint16_t read_word(std::uint8_t sid) {
        const auto packet = read_packet(sid);
        std::array<std::uint8_t, tcp_header_size + 16> in{};
        if (!send_all(packet.data(), packet.size()) || !receive(in.data(), in.size()))
            return 0xFFFF;
        if (in[tcp_header_size + 9] != sid) return 0xFFFE;
        return static_cast<std::uint16_t>((in[tcp_header_size + 12] << 8) |
                                          in[tcp_header_size + 13]);
    }
    [[nodiscard]] int fd() const noexcept { return fd_; }
    // The client node the handshake gave this connection.
    [[nodiscard]] std::uint8_t node() const noexcept { return node_; }
    // One whole FINS/TCP packet (header and data); empty on EOF, error or timeout.
    std::vector<std::uint8_t> receive_packet() {
        std::vector<std::uint8_t> packet(tcp_header_size);
        if (!receive(packet.data(), packet.size())) return {};
        const std::uint32_t length = (std::uint32_t{packet[4]} << 24) |
                                     (std::uint32_t{packet[5]} << 16) |
                                     (std::uint32_t{packet[6]} << 8) | packet[7];
        if (length < 8 || length > tcp_max_length) return {};
        packet.resize(tcp_header_size + length - 8);
        if (!receive(packet.data() + tcp_header_size, length - 8)) return {};
        return packet;
    }
    // Sends `frame` in a FRAME SEND packet.
    bool send_frame(const std::vector<std::uint8_t>& frame) {
        std::vector<std::uint8_t> packet(tcp_header_size + frame.size());
        ByteWriter w{packet};
        write_tcp_header(w, TcpCommand::frame, frame.size());
        w.bytes(frame);
        return send_all(packet.data(), packet.size());
    }
    bool send_all(const std::uint8_t* p, std::size_t n) {
        return ::send(fd_, p, n, MSG_NOSIGNAL) == static_cast<ssize_t>(n);
    }
    bool receive(std::uint8_t* p, std::size_t n) {
        while (n > 0) {
            const ssize_t r = ::recv(fd_, p, n, 0);
            if (r <= 0) return false;
            p += r;
            n -= static_cast<std::size_t>(r);
        }
        return true;
    }

  private:
    int fd_ = -1;
    bool connected_ = false;
    std::uint8_t node_ = 0;
};

}  // namespace fins::test
