// Blocking loopback sockets for tests that must control every byte on the wire. Every
// receive has a timeout (SO_RCVTIMEO), so a misbehaving server fails the test instead
// of hanging it.
#pragma once

#include <sys/socket.h>
#include <sys/time.h>

#include <cerrno>
#include <cstdint>
#include <string>
#include <system_error>
#include <vector>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/write.hpp>

#include "../fuzz/corpus_dump.hpp"
#include "fins/frame.hpp"
#include "fins/tcp.hpp"
#include "transport/asio.hpp"

namespace fins::test {

inline void set_receive_timeout(int fd, int seconds) {
    timeval tv{seconds, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
}

// A FINS request frame: header to node 1 from node `source`, command, parameters.
inline std::vector<std::uint8_t> request_frame(CommandCode code,
                                               const std::vector<std::uint8_t>& params,
                                               std::uint8_t sid = 0x11,
                                               std::uint8_t source = 0xEF) {
    Header h;
    h.destination = {0, 0, 0};
    h.source = {0, source, 0};
    h.service_id = sid;
    std::vector<std::uint8_t> out(max_frame_size);
    auto n = encode_request(h, code, params, out);
    out.resize(n.value_or(0));
    return out;
}

inline std::vector<std::uint8_t> tcp_packet(TcpCommand command,
                                            const std::vector<std::uint8_t>& data) {
    std::vector<std::uint8_t> out(tcp_header_size + data.size());
    ByteWriter w{out};
    write_tcp_header(w, command, data.size());
    w.bytes(data);
    return out;
}

class RawTcp {
  public:
    RawTcp(asio::io_context& io, const std::string& host, std::uint16_t port) : socket_(io) {
        socket_.connect({asio::ip::make_address(host), port});
        socket_.set_option(asio::ip::tcp::no_delay(true));
        set_receive_timeout(socket_.native_handle(), 5);
    }
    ~RawTcp() { fuzz::dump_test_bytes("tcp_stream", sent_); }  // FINS_FUZZ_DUMP
    RawTcp(RawTcp&&) = default;
    RawTcp& operator=(RawTcp&&) = default;
    void send(const std::vector<std::uint8_t>& bytes) {
        sent_.insert(sent_.end(), bytes.begin(), bytes.end());
        asio::write(socket_, asio::buffer(bytes));
    }
    // Reads one whole FINS/TCP packet; empty on EOF, error or timeout.
    std::vector<std::uint8_t> receive_packet() {
        std::vector<std::uint8_t> head(tcp_header_size);
        if (!read_exact(head.data(), head.size())) return {};
        const std::uint32_t length = (std::uint32_t{head[4]} << 24) |
                                     (std::uint32_t{head[5]} << 16) |
                                     (std::uint32_t{head[6]} << 8) | head[7];
        if (length < 8 || length > tcp_max_length) return head;
        std::vector<std::uint8_t> rest(length - 8);
        if (!read_exact(rest.data(), rest.size())) return {};
        head.insert(head.end(), rest.begin(), rest.end());
        return head;
    }
    // Handshake asking for `node` (0 = allocate); returns the 24-byte answer.
    std::vector<std::uint8_t> handshake(std::uint8_t node = 0) {
        std::vector<std::uint8_t> req(20);
        ByteWriter w{req};
        write_node_address_request(w, node);
        send(req);
        return receive_packet();
    }
    // True when the server closed the connection (EOF or reset) within the receive
    // timeout; false on a byte or on the timeout.
    bool closed_by_peer() {
        std::uint8_t b = 0;
        const ssize_t n = ::recv(socket_.native_handle(), &b, 1, 0);
        return n == 0 || (n < 0 && errno == ECONNRESET);
    }
    void close() {
        boost::system::error_code ec;
        socket_.close(ec);
    }
    [[nodiscard]] int native_handle() { return socket_.native_handle(); }
    // Why the last receive_packet() came back empty (eof = the peer's FIN).
    [[nodiscard]] boost::system::error_code last_error() const { return last_error_; }

  private:
    // Plain recv(): Asio's blocking read turns SO_RCVTIMEO's EAGAIN into an endless
    // poll(), which would hang a test instead of failing it.
    bool read_exact(std::uint8_t* p, std::size_t n) {
        last_error_.clear();
        while (n > 0) {
            const ssize_t r = ::recv(socket_.native_handle(), p, n, 0);
            if (r == 0) {
                last_error_ = asio::error::eof;
                return false;
            }
            if (r < 0) {
                if (errno == EINTR) continue;
                last_error_ =
                    errno == EAGAIN || errno == EWOULDBLOCK
                        ? boost::system::error_code(ETIMEDOUT, boost::system::system_category())
                        : boost::system::error_code(errno, boost::system::system_category());
                return false;
            }
            p += r;
            n -= static_cast<std::size_t>(r);
        }
        return true;
    }

    asio::ip::tcp::socket socket_;
    boost::system::error_code last_error_;
    std::vector<std::uint8_t> sent_;  // everything sent, for the fuzz corpus
};

inline std::uint32_t be32(const std::vector<std::uint8_t>& b, std::size_t at) {
    return (std::uint32_t{b[at]} << 24) | (std::uint32_t{b[at + 1]} << 16) |
           (std::uint32_t{b[at + 2]} << 8) | b[at + 3];
}

// End code of a FINS response frame (bytes 12-13), or of the frame inside a TCP packet.
inline std::uint16_t end_code_of(const std::vector<std::uint8_t>& frame, std::size_t offset = 0) {
    if (frame.size() < offset + 14) return 0xFFFF;
    return static_cast<std::uint16_t>((frame[offset + 12] << 8) | frame[offset + 13]);
}

}  // namespace fins::test
