// finsd as a FINS/TCP client: one connection to a remote FINS/TCP server, opened by
// this node ([[remote]] with transport = "tcp"), over which this node's Send, Rcv and
// SendCmd reach that remote node (W596 3).
//
// W596 1-4: the 16 FINS/TCP connections are "server and client connections" together;
// W596 2-1: the FINS/TCP Connection Settings select Server or Client per connection. A
// configured client connection so holds one of the 16 for as long as finsd runs
// (Server::start reserves it in the TcpNodeTable): the server side accepts 16 minus
// the clients, and refuses the next with 00000020 "All connections are in use".
//
// The connection (transport/tcp_transport.hpp does the envelope, W421 7-4):
//   connect -> NODE ADDRESS DATA SEND with `client_node` (0: the server allocates one)
//   -> the server's answer gives our client node and its own node, which must be the
//   [[remote]]'s `node` (else it is the wrong node: closed, retried later) ->
//   established: FRAME SEND both ways.
// Everything is asynchronous on finsd's io_context: connect and handshake never block
// the event loop; the whole open is bounded by `open_timeout`.
// Down (refused, timed out, closed by the peer): retried after a back-off that doubles
// from `retry_min` up to `retry_max`, each delay drawn in [delay / 2, delay] (jitter:
// several finsd restarting together do not reconnect in step); the first retry after an
// established connection drops waits `retry_min`. W421 7-4: a client unit "keeps
// retrying the connect every few seconds".
// A server gone without closing (power off, cable pulled; what an NX does is not in
// W596 or W421, chosen here): TCP keep-alive on the connection (TcpClientTiming::
// keepalive) ends it within idle + interval x count, 30 s by default, and a server that
// holds the connection but answers nothing is dropped after `max_unanswered`
// consecutive instruction frames on it got no answer in time (the instruction
// transport reports each, note_unanswered(); any frame received resets the count).
// Either way the connection is reopened as after any drop.
// Frames this node sends carry the client node as SA1 (W421 7-4: "substituting the
// value allocated in SA1"). Answers (ICF bit 6) from the remote node go to the
// response hook. FRAME SEND is full duplex (W421 7-4): a command the server sends to
// our client node is served by this node's dispatcher as one to this node (its DA1 is
// the client node, the node's name on this connection), and answered on the connection
// with the client node as SA1.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "fins/frame.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/instructions/instruction_udp.hpp"
#include "transport/asio.hpp"
#include "transport/tcp_transport.hpp"

namespace fins::server {

struct TcpClientTiming {
    std::chrono::milliseconds open_timeout{10'000};
    std::chrono::milliseconds retry_min{100};
    std::chrono::milliseconds retry_max{10'000};
    // Keep-alive on the socket: a dead server is noticed within 10 + 5 x 4 = 30 s.
    transport::TransportOptions::KeepAlive keepalive{std::chrono::seconds(10),
                                                     std::chrono::seconds(5), 4};
    // Consecutive unanswered instruction frames that close the connection; 0: never.
    unsigned max_unanswered = 3;
};

// The back-off before the next attempt after `failures` failed opens in a row:
// retry_min x 2^failures, at most retry_max (the jitter then draws in [half, all]).
std::chrono::milliseconds tcp_client_retry_delay(unsigned failures,
                                                 const TcpClientTiming& timing) noexcept;

class TcpClient {
  public:
    struct Counters {
        std::uint64_t connects = 0;   // handshakes that succeeded
        std::uint64_t failures = 0;   // opens that failed (refused, timeout, wrong node)
        std::uint64_t drops = 0;      // established connections that ended
        std::uint64_t unmatched = 0;  // frames received that nobody took
        std::uint64_t served = 0;     // commands from the server answered
        std::uint64_t silent = 0;     // connections closed for max_unanswered timeouts
    };
    // Gets each answer received while established; true when it was taken.
    using ResponseHook = std::function<bool(Bytes frame, const TcpClient& connection)>;

    // `remote`: the [[remote]] entry (transport = "tcp"); `dispatcher`: this node's, which
    // serves the commands the server sends on the connection.
    TcpClient(asio::io_context& io, Dispatcher& dispatcher, RemoteNode remote,
              TcpClientTiming timing);
    ~TcpClient();
    TcpClient(const TcpClient&) = delete;
    TcpClient& operator=(const TcpClient&) = delete;

    void set_response_hook(ResponseHook hook) { response_hook_ = std::move(hook); }
    // Opens the connection now, and again whenever it is down, until stop().
    void start();
    void stop();

    [[nodiscard]] bool established() const noexcept { return established_; }
    // This node's node number on the connection (the handshake's); 0 while down.
    [[nodiscard]] std::uint8_t client_node() const noexcept { return client_node_; }
    [[nodiscard]] const RemoteNode& remote() const noexcept { return remote_; }
    [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
    // True when `destination` is the remote node (network 00 and this node's network
    // both name the local network).
    [[nodiscard]] bool reaches(const NodeAddress& destination) const noexcept;
    // Sends a frame of this node's with SA1 = client_node(). False while not established.
    bool send_frame(Bytes frame);
    // A frame sent on the connection got no answer in time: the max_unanswered-th in a
    // row closes the connection and opens it again.
    void note_unanswered();
    // The connection's socket (tests inspect its options); -1 while down.
    [[nodiscard]] transport::os::NativeSocket native_handle() const noexcept {
        return transport_.native_handle();
    }

  private:
    void open();
    void on_open(Result<transport::LinkInfo> link);
    void on_frame(Bytes frame);
    void serve(Bytes command);
    void on_close(boost::system::error_code reason);
    void drop();
    void retry_later(std::chrono::milliseconds delay);
    [[nodiscard]] std::chrono::milliseconds next_delay() noexcept;

    Dispatcher& dispatcher_;
    RemoteNode remote_;
    NodeAddress self_;
    TcpClientTiming timing_;
    transport::TcpTransport transport_;
    asio::steady_timer retry_timer_;
    ResponseHook response_hook_;
    bool running_ = false;
    bool established_ = false;
    std::uint8_t client_node_ = 0;
    unsigned failures_in_row_ = 0;
    unsigned unanswered_in_row_ = 0;
    std::minstd_rand random_;
    Counters counters_;
    std::array<std::uint8_t, max_frame_size> out_{};
    std::array<std::uint8_t, max_frame_size> request_{};
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fins::server
