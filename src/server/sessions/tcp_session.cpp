#include "server/sessions/tcp_session.hpp"

#include "transport/socket_headers.hpp"
#include "transport/socket_os.hpp"

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <cstring>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>

#include "fins/frame.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/sessions/failure_boundary.hpp"
#include "transport/asio.hpp"

namespace fins::server {

namespace {

// FINS header offsets of the source network and node (W342 3-3-3: ICF RSV GCT DNA DA1
// DA2 SNA SA1 SA2 SID).
constexpr std::size_t source_network_offset = 6;
constexpr std::size_t source_node_offset = 7;

#ifdef TCP_QUICKACK
using quick_ack = asio::detail::socket_option::boolean<IPPROTO_TCP, TCP_QUICKACK>;
#endif

}  // namespace

TcpSession::TcpSession(asio::ip::tcp::socket socket, Dispatcher& dispatcher, TcpNodeTable& nodes,
                       const TcpLimits& limits)
    : socket_(std::move(socket)),
      dispatcher_(dispatcher),
      nodes_(nodes),
      limits_(limits),
      timer_(socket_.get_executor()) {
    boost::system::error_code ignored;
    const auto remote = socket_.remote_endpoint(ignored);
    peer_ = remote.address();
    peer_port_ = remote.port();
}

TcpSession::~TcpSession() {
    nodes_.release(client_node_, this);
}

void TcpSession::start() {
    boost::system::error_code ignored;
    // Never let a response sit behind Nagle waiting for the client's delayed ACK.
    socket_.set_option(asio::ip::tcp::no_delay(true), ignored);
    transport::os::prepare_nonblocking(socket_.native_handle());
    if (const auto ec = set_keepalive(socket_, limits_.keepalive))
        spdlog::debug("fins/tcp: keep-alive: {}", ec.message());
    set_deadline(Deadline::handshake, limits_.handshake_timeout);
    on_readable();
}

void TcpSession::close() {
    if (state_ == State::closed) return;
    state_ = State::closed;
    ++timer_generation_;
    timer_.cancel();
    nodes_.release(client_node_, this);
    client_node_ = 0;
    boost::system::error_code ignored;
    socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
    socket_.close(ignored);
}

void TcpSession::wait_readable() {
    socket_.async_wait(asio::socket_base::wait_read,
                       [self = shared_from_this()](boost::system::error_code ec) {
                           if (ec == asio::error::operation_aborted) return;
                           self->on_readable();
                       });
}

void TcpSession::on_readable() {
    const auto fd = socket_.native_handle();
    for (unsigned round = 0; round < rounds_per_turn; ++round) {
        if (state_ != State::handshake && state_ != State::established) return;
        // serve_buffered() leaves at most one partial packet, so there is room for one.
        const std::size_t room = in_.size() - in_size_;
        const auto got = transport::os::receive_now(fd, in_.data() + in_size_, room);
        using Kind = transport::os::Moved::Kind;
        if (got.kind == Kind::interrupted) continue;
        if (got.kind == Kind::would_block) break;
        if (got.kind == Kind::failed) {
            spdlog::debug("fins/tcp: read failed: {}", transport::os::error_text(got.error));
            close();
            return;
        }
        const std::size_t n = got.bytes;
        if (n == 0) {  // the peer closed its side
            close();
            return;
        }
        in_size_ += n;
        if (!serve_buffered()) return;
        // A lone request is the one-in-flight client: the next cannot come before it has
        // this answer, so reading again would only find nothing. The wait's re-arm
        // (EPOLL_CTL_MOD) reports data that does come meanwhile.
        if (served_ <= 1 && n < room) break;
        if (round + 1 == rounds_per_turn) {
            // Still busy: let the other sessions' ready handlers run, then go on.
            asio::post(socket_.get_executor(), [self = shared_from_this()] {
                if (self->open()) self->on_readable();
            });
            return;
        }
    }
    wait_readable();
}

void TcpSession::resume() {
    if (serve_buffered()) on_readable();
}

bool TcpSession::serve_buffered() {
    served_ = 0;
    std::size_t start = 0;
    bool go_on = true;
    bool answered = true;  // the last packet brings an answer, which carries our ACK
    while (go_on && (state_ == State::handshake || state_ == State::established)) {
        const TcpParse parsed = parse_tcp_frame({in_.data() + start, in_size_ - start});
        if (parsed.status == TcpParse::Status::need_more) break;
        if (parsed.status == TcpParse::Status::error) {
            ByteWriter w{out_};
            write_tcp_error(w, TcpCommand::frame_error, parsed.error);
            log_summarised(nodes_.log().envelope_errors, spdlog::level::warn,
                           "fins/tcp: {}: envelope error {:#04x}, closing", peer_.to_string(),
                           static_cast<int>(parsed.error));
            start = in_size_;
            go_on = send_answer(w.size(), true);
            break;
        }
        const bool keep_open = handle_packet(parsed.packet);
        answered = out_size_pending_ > 0;
        start += parsed.consumed;
        ++served_;
        // A complete packet: what follows is a new packet with its own frame deadline.
        if (state_ == State::established) deadline_kind_ = Deadline::idle;
        if (out_size_pending_ > 0 || !keep_open) go_on = send_answer(out_size_pending_, !keep_open);
    }
    // The packets' data views pointed into in_; only now may the rest move to the front.
    std::memmove(in_.data(), in_.data() + start, in_size_ - start);
    in_size_ -= start;
    if (!go_on || state_ != State::established) return go_on;
    // The handshake deadline runs from accept; afterwards a packet that has begun must
    // end within frame_timeout, and silence is bounded by idle_timeout.
    if (in_size_ == 0)
        set_deadline(Deadline::idle, limits_.idle_timeout);
    else if (deadline_kind_ != Deadline::frame)
        set_deadline(Deadline::frame, limits_.frame_timeout);
        // A client that writes the FINS/TCP header and the frame separately without
        // TCP_NODELAY holds the frame until its header is acknowledged, and a frame that
        // asks for no response gets no answer to carry the ACK. Linux delays that ACK
        // (~40 ms); quick-ack mode does not stick, so re-arm it (issue 6 item 13).
#ifdef TCP_QUICKACK
    if (in_size_ > 0 || !answered) {
        boost::system::error_code ignored;
        socket_.set_option(quick_ack(true), ignored);
    }
#else
    (void)answered;  // Windows acknowledges by its own rule (no quick-ack option)
#endif
    return true;
}

bool TcpSession::send_answer(std::size_t size, bool close_after) {
    if (close_after || write_ != Write::idle) {
        send_and_continue(size, close_after);
        return false;
    }
    transport::os::Moved sent;
    sent.kind = transport::os::Moved::Kind::interrupted;
    for (int attempt = 0; attempt < 4 && sent.kind == transport::os::Moved::Kind::interrupted;
         ++attempt)
        sent = transport::os::send_now(socket_.native_handle(), out_.data(), size);
    using Kind = transport::os::Moved::Kind;
    if (sent.kind == Kind::done && sent.bytes == size) return true;
    if (sent.kind == Kind::failed || sent.kind == Kind::interrupted) {
        spdlog::debug("fins/tcp: write failed: {}", transport::os::error_text(sent.error));
        close();
        return false;
    }
    // The send buffer is full: the rest goes out asynchronously, reading waits for it.
    const std::size_t done = sent.kind == Kind::done ? sent.bytes : 0;
    std::memmove(out_.data(), out_.data() + done, size - done);
    send_and_continue(size - done, false);
    return false;
}

bool TcpSession::handle_packet(const TcpPacket& packet) {
    out_size_pending_ = 0;
    const auto command = static_cast<TcpCommand>(packet.command);
    if (state_ == State::handshake) {
        if (command == TcpCommand::node_address_request) return handshake(packet);
        ByteWriter w{out_};
        write_tcp_error(w, TcpCommand::frame_error, TcpError::command_not_supported);
        out_size_pending_ = w.size();
        return false;
    }
    ByteWriter w{out_};
    if (command != TcpCommand::frame) {
        // A second handshake or any other command on an open connection (frames 3.4 step 5).
        write_tcp_error(w, TcpCommand::frame_error, TcpError::command_not_supported);
        out_size_pending_ = w.size();
        return false;
    }
    if (!from_bound_node(packet.data)) {
        // Not executed as another node and not answered: W421 sends a node's answers only
        // on the connection paired with it. One warning per connection, and at most one
        // per interval for all connections (tcp_session_log.hpp): no log flood.
        if (logged_foreign_source_) {
            spdlog::debug("fins/tcp: {}: dropped a frame from {}.{} on the connection of node {}",
                          peer_.to_string(), packet.data[source_network_offset],
                          packet.data[source_node_offset], client_node_);
        } else {
            logged_foreign_source_ = true;
            log_summarised(nodes_.log().foreign_sources, spdlog::level::warn,
                           "fins/tcp: {}: dropped a frame from {}.{} on the connection of node {}",
                           peer_.to_string(), packet.data[source_network_offset],
                           packet.data[source_node_offset], client_node_);
        }
        return true;
    }
    // An answer to one of this node's own instructions, sent to the client's node.
    if (response_hook_ && !packet.data.empty() && (packet.data[0] & icf_response) != 0 &&
        take_response_guarded([&] { return response_hook_(packet.data); }))
        return true;
    // Reserve the envelope header, let the dispatcher write the FINS response after it.
    const MutableBytes frame_out{out_.data() + tcp_header_size, max_frame_size};
    const RequestContext context{Link::tcp, std::chrono::system_clock::now(), this};
    const std::size_t n = handle_guarded(dispatcher_, packet.data, frame_out, context);
    if (n > 0) {
        write_tcp_header(w, TcpCommand::frame, n);
        out_size_pending_ = tcp_header_size + n;
    }
    return true;
}

bool TcpSession::handshake(const TcpPacket& packet) {
    ByteWriter w{out_};
    const auto requested = decode_node_address_request(packet.data);
    // The refusal echoes the requested value whole (00000105 stays 00000105).
    ByteReader raw(packet.data);
    const std::uint32_t echoed = packet.data.size() >= 4 ? raw.u32() : 0;
    Result<std::uint8_t> claimed = requested;
    if (requested) {
        claimed = nodes_.claim(*requested, this);
    } else if (requested.error() != TcpError::client_node_out_of_range) {
        write_tcp_error(w, TcpCommand::frame_error, TcpError::data_length_too_long);
        out_size_pending_ = w.size();
        return false;
    }
    if (!claimed) {
        // W421 7-4: a client with the same IP address and node as an open connection makes
        // the server probe that connection with command 6; the newcomer is refused (0x21)
        // whatever the probe shows.
        if (claimed.error() == TcpError::node_already_connected)
            if (TcpSession* holder = nodes_.owner(*requested);
                holder != nullptr && holder->peer_address() == peer_)
                holder->confirm_connection();
        // W421 7-4: the error goes back in command 1, then the server closes.
        write_node_address_response(w, echoed, dispatcher_.self().node,
                                    static_cast<std::uint32_t>(claimed.error().value()));
        out_size_pending_ = w.size();
        // The node as the client sent it, in decimal (0 asks for one), and why.
        log_summarised(nodes_.log().refused, spdlog::level::info,
                       "fins/tcp: {}: refused client node {}{}: {}", peer_.to_string(), echoed,
                       echoed == 0 ? " (automatic allocation)" : "", claimed.error().message());
        return false;
    }
    client_node_ = *claimed;
    state_ = State::established;
    write_node_address_response(w, client_node_, dispatcher_.self().node);
    out_size_pending_ = w.size();
    log_summarised(nodes_.log().connected, spdlog::level::info,
                   "fins/tcp: {}: client node {} connected", peer_.to_string(), client_node_);
    return true;
}

bool TcpSession::from_bound_node(Bytes frame) const noexcept {
    // Too short to name a source: the dispatcher drops it (there is no SID to answer).
    if (frame.size() <= source_node_offset) return true;
    const std::uint8_t network = frame[source_network_offset];
    const bool local = network == local_network || network == dispatcher_.self().network;
    return local && frame[source_node_offset] == client_node_;
}

void TcpSession::start_write(Write what) noexcept {
    assert(write_ == Write::idle && what != Write::idle);
    write_ = what;
}

void TcpSession::write_next() {
    if (write_ != Write::idle) return;
    if (deferred_) {
        const DeferredResponse next = *deferred_;
        deferred_.reset();
        send_and_continue(next.size, next.close_after);
    } else if (confirm_wanted_) {
        confirm_wanted_ = false;
        send_confirmation();
    } else if (!late_.empty()) {
        write_late();
    }
}

void TcpSession::send_and_continue(std::size_t size, bool close_after) {
    if (write_ != Write::idle) {
        // Command 6 or a late frame is on its way; this packet follows it whole.
        deferred_ = DeferredResponse{size, close_after};
        return;
    }
    start_write(Write::response);
    // The peer must take the response: a client that stops reading is a stalled frame.
    if (state_ == State::established) set_deadline(Deadline::frame, limits_.frame_timeout);
    auto self = shared_from_this();
    // One write per response: clients that read one response per recv() depend on it.
    asio::async_write(socket_, asio::buffer(out_.data(), size),
                      [self, close_after](boost::system::error_code ec, std::size_t) {
                          self->write_ = Write::idle;
                          if (!self->open()) return;
                          if (ec) {
                              self->close();
                              return;
                          }
                          if (close_after) {
                              self->close_after_notice();
                              return;
                          }
                          self->write_next();
                          self->resume();
                      });
}

void TcpSession::confirm_connection() {
    if (state_ != State::established || write_ == Write::confirmation) return;
    if (write_ != Write::idle) {
        confirm_wanted_ = true;
        return;
    }
    send_confirmation();
}

void TcpSession::send_confirmation() {
    start_write(Write::confirmation);
    ByteWriter w{confirmation_};
    write_tcp_header(w, TcpCommand::connection_confirmation, 0);
    log_summarised(nodes_.log().confirmations, spdlog::level::info,
                   "fins/tcp: {}: node {} asked for again, confirming the connection",
                   peer_.to_string(), client_node_);
    auto self = shared_from_this();
    asio::async_write(socket_, asio::buffer(confirmation_),
                      [self](boost::system::error_code ec, std::size_t) {
                          self->write_ = Write::idle;
                          if (!self->open()) return;
                          if (ec) {
                              self->close();
                              return;
                          }
                          self->write_next();
                      });
}

bool TcpSession::push_frame(Bytes frame) {
    if (state_ != State::established || late_.size() >= max_late || frame.size() > max_frame_size)
        return false;
    queue_late(frame);
    return true;
}

Completion TcpSession::defer() {
    return [weak = weak_from_this()](Bytes frame) {
        if (auto self = weak.lock()) self->queue_late(frame);
    };
}

void TcpSession::queue_late(Bytes frame) {
    if (state_ != State::established) return;
    if (late_.size() >= max_late) {
        log_summarised(nodes_.log().late_dropped, spdlog::level::warn,
                       "fins/tcp: {}: late answer dropped (peer not reading)", peer_.to_string());
        return;
    }
    std::vector<std::uint8_t> packet(tcp_header_size + frame.size());
    ByteWriter w{packet};
    write_tcp_header(w, TcpCommand::frame, frame.size());
    w.bytes(frame);
    late_.push_back(std::move(packet));
    if (write_ == Write::idle) write_late();
}

void TcpSession::write_late() {
    start_write(Write::late_frame);
    auto self = shared_from_this();
    asio::async_write(socket_, asio::buffer(late_.front()),
                      [self](boost::system::error_code ec, std::size_t) {
                          self->write_ = Write::idle;
                          if (!self->late_.empty()) self->late_.pop_front();
                          if (!self->open()) return;
                          if (ec) {
                              self->close();
                              return;
                          }
                          self->write_next();
                      });
}

}  // namespace fins::server
