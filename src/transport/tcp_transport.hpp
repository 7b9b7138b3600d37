// FINS/TCP client transport (W421 7-4, frames section 3).
//
// Open: resolve host:port, connect (first address that answers), TCP_NODELAY, send
// NODE ADDRESS DATA SEND (command 0) with TransportOptions::requested_node (0 = ask the
// server to allocate), read the 24-byte command-1 answer and learn the client node and
// the server node (LinkInfo). A command 1 with a non-zero error code, or a command 3,
// fails the open with that TcpError (e.g. 0x21 node_already_connected); anything else
// fails it with ClientError::handshake_failed. The whole open is bounded by
// TransportOptions::open_timeout. TransportOptions::keepalive, when set, goes on the
// socket once connected.
//
// Open: every packet is parsed with parse_tcp_frame(), which copes with packets split
// across reads or glued together. Command 2 delivers its FINS frame; command 6
// (connection confirmation) is ignored as frames 3.4 says; command 3 closes the
// transport with its TcpError; an envelope error, or command 0/1/unknown, is answered
// with command 3 (frames 3.4 items 4-5) and closes with that TcpError. The peer
// closing or resetting closes with ClientError::connection_closed. peer_gone() peeks
// (MSG_PEEK, non-blocking) for an end of stream or reset that nobody has read yet.
// Frames sent from inside the frame handler (completion callbacks that send the next
// request) are gathered and written together once the read's packets are handled.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "fins/tcp.hpp"
#include "transport/asio.hpp"
#include "transport/socket_os.hpp"
#include "transport/socket_transport.hpp"

namespace fins::transport {

class TcpTransport final : public SocketTransport<asio::ip::tcp> {
  public:
    TcpTransport(asio::io_context& io, TransportOptions options);
    ~TcpTransport() override;

    void async_open(OpenHandler done) override;
    void send(Bytes frame) override;
    void close() override;
    [[nodiscard]] bool peer_gone() override;
    // Reads that returned bytes since construction (handshake included); lets tests see
    // how the bytes of a packet actually arrived.
    [[nodiscard]] std::uint64_t reads() const noexcept { return reads_; }
    // The socket, for inspecting its options (tests); os::invalid_socket (-1) while closed.
    [[nodiscard]] os::NativeSocket native_handle() const noexcept { return fd_; }

  private:
    void on_connected();
    // TransportOptions::keepalive on the connected socket.
    void set_keepalive(boost::system::error_code& ec);
    void read_handshake();
    void finish_open(Result<LinkInfo> result) override;
    void read_frames();
    // Parses what is buffered; false once the transport was closed meanwhile.
    bool process_frames();
    void send_error_and_fail(TcpError error);
    void write_raw(Bytes first, Bytes second);
    void write_next();
    void consume(std::size_t n) noexcept;
    void uncork();

    os::NativeSocket fd_ = os::invalid_socket;  // socket_'s, once connected
    std::size_t front_written_ = 0;             // bytes of queue_.front() already written
    std::array<std::uint8_t, 20> hello_{};
    // Room for two maximal packets: whatever is left after parsing fits with room to read.
    std::array<std::uint8_t, 2 * tcp_max_packet> rx_{};
    std::size_t rx_size_ = 0;
    std::uint64_t reads_ = 0;
    // While the answers of one read are handed out, the requests their callbacks send
    // are gathered here and leave in one write when the read is done.
    bool corked_ = false;
    std::vector<std::uint8_t> cork_;
};

}  // namespace fins::transport
