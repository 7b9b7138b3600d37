#include "server/tcp_session.hpp"

#include <netinet/in.h>
#include <netinet/tcp.h>

#include <cstring>

#include <spdlog/spdlog.h>
#include <asio/write.hpp>

#include "fins/frame.hpp"
#include "server/dispatcher.hpp"

namespace fins::server {

namespace {

// Auto-assigned client nodes: CS/CJ Ethernet units hand out 239-254 to FINS/TCP clients
// by default (one per connection); we fall back to the rest of 1-254 when those are taken.
constexpr std::uint8_t first_auto_node = 239;

using quick_ack = asio::detail::socket_option::boolean<IPPROTO_TCP, TCP_QUICKACK>;

// Must what the client sent be acknowledged now? When `buffer` ends inside a FINS/TCP
// packet the client may be holding the rest (Nagle) until it is; when its last packet
// is a frame that asks for no response, no answer will carry the ACK. Otherwise the
// answer we are about to send carries it.
bool needs_prompt_ack(Bytes buffer) noexcept {
    bool answered = true;
    while (!buffer.empty()) {
        const TcpParse parsed = parse_tcp_frame(buffer);
        if (parsed.status != TcpParse::Status::packet)
            return parsed.status == TcpParse::Status::need_more;
        answered = parsed.packet.command != static_cast<std::uint32_t>(TcpCommand::frame) ||
                   parsed.packet.data.empty() || (parsed.packet.data[0] & icf_no_response) == 0;
        buffer = buffer.subspan(parsed.consumed);
    }
    return !answered;
}

}  // namespace

Result<std::uint8_t> TcpNodeTable::claim(std::uint8_t requested) noexcept {
    if (full()) return Unexpected(make_error_code(TcpError::all_connections_in_use));
    std::uint8_t node = requested;
    if (requested == 0) {
        auto free = [&](unsigned n) { return n != server_node_ && !used_[n]; };
        node = 0;
        for (unsigned n = first_auto_node; n <= 254 && node == 0; ++n)
            if (free(n)) node = static_cast<std::uint8_t>(n);
        for (unsigned n = 1; n < first_auto_node && node == 0; ++n)
            if (free(n)) node = static_cast<std::uint8_t>(n);
        if (node == 0) return Unexpected(make_error_code(TcpError::no_node_available));
    } else if (requested == 255) {
        return Unexpected(make_error_code(TcpError::client_node_out_of_range));
    } else if (requested == server_node_) {
        return Unexpected(make_error_code(TcpError::same_node_as_server));
    } else if (used_[requested]) {
        return Unexpected(make_error_code(TcpError::node_already_connected));
    }
    used_[node] = true;
    ++count_;
    return node;
}

void TcpNodeTable::release(std::uint8_t node) noexcept {
    if (node != 0 && used_[node]) {
        used_[node] = false;
        --count_;
    }
}

TcpSession::TcpSession(asio::ip::tcp::socket socket, Dispatcher& dispatcher, TcpNodeTable& nodes)
    : socket_(std::move(socket)), dispatcher_(dispatcher), nodes_(nodes) {}

TcpSession::~TcpSession() {
    nodes_.release(client_node_);
}

void TcpSession::start() {
    std::error_code ignored;
    // Never let a response sit behind Nagle waiting for the client's delayed ACK.
    socket_.set_option(asio::ip::tcp::no_delay(true), ignored);
    read_more();
}

void TcpSession::close() {
    std::error_code ignored;
    socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
    socket_.close(ignored);
    nodes_.release(client_node_);
    client_node_ = 0;
}

void TcpSession::read_more() {
    auto self = shared_from_this();
    socket_.async_read_some(
        asio::buffer(in_.data() + in_size_, in_.size() - in_size_),
        [self](std::error_code ec, std::size_t n) {
            if (ec) {
                if (ec != asio::error::operation_aborted && ec != asio::error::eof)
                    spdlog::debug("fins/tcp: read failed: {}", ec.message());
                self->close();
                return;
            }
            self->in_size_ += n;
            // A client that writes the FINS/TCP header and the frame separately without
            // TCP_NODELAY holds the frame until its header is acknowledged. Linux delays
            // that ACK (~40 ms) once we answer promptly; quick-ack mode does not stick,
            // so re-arm it after a read that no answer follows (issue 6 item 13).
            if (needs_prompt_ack({self->in_.data(), self->in_size_})) {
                std::error_code ignored;
                self->socket_.set_option(quick_ack(true), ignored);
            }
            self->process();
        });
}

void TcpSession::process() {
    if (!socket_.is_open()) return;
    const Bytes available{in_.data(), in_size_};
    const TcpParse parsed = parse_tcp_frame(available);
    switch (parsed.status) {
        case TcpParse::Status::need_more:
            // Keep the partial packet at the front so the next read appends to it.
            read_more();
            return;
        case TcpParse::Status::error: {
            ByteWriter w{out_};
            write_tcp_error(w, TcpCommand::frame_error, parsed.error);
            spdlog::warn("fins/tcp: envelope error {:#04x}, closing",
                         static_cast<int>(parsed.error));
            in_size_ = 0;
            send_and_continue(w.size(), true);
            return;
        }
        case TcpParse::Status::packet:
            break;
    }
    const bool keep_open = handle_packet(parsed.packet);
    // The packet's data view points into in_; only now may it move.
    std::memmove(in_.data(), in_.data() + parsed.consumed, in_size_ - parsed.consumed);
    in_size_ -= parsed.consumed;
    if (out_size_pending_ > 0 || !keep_open) {
        send_and_continue(out_size_pending_, !keep_open);
        return;
    }
    process();
}

bool TcpSession::handle_packet(const TcpPacket& packet) {
    ByteWriter w{out_};
    out_size_pending_ = 0;
    const auto command = static_cast<TcpCommand>(packet.command);
    if (client_node_ == 0) {
        if (command != TcpCommand::node_address_request) {
            write_tcp_error(w, TcpCommand::frame_error, TcpError::command_not_supported);
            out_size_pending_ = w.size();
            return false;
        }
        auto requested = decode_node_address_request(packet.data);
        if (!requested) {
            write_tcp_error(w, TcpCommand::frame_error, TcpError::data_length_too_long);
            out_size_pending_ = w.size();
            return false;
        }
        auto claimed = nodes_.claim(*requested);
        if (!claimed) {
            // W421 7-4: the error goes back in command 1, then the server closes.
            write_node_address_response(w, *requested, dispatcher_.self().node,
                                        static_cast<std::uint32_t>(claimed.error().value()));
            out_size_pending_ = w.size();
            spdlog::info("fins/tcp: refused client node {}: {}", *requested,
                         claimed.error().message());
            return false;
        }
        client_node_ = *claimed;
        write_node_address_response(w, client_node_, dispatcher_.self().node);
        out_size_pending_ = w.size();
        spdlog::info("fins/tcp: client node {} connected", client_node_);
        return true;
    }
    if (command != TcpCommand::frame) {
        // A second handshake or any other command on an open connection (frames 3.4 step 5).
        write_tcp_error(w, TcpCommand::frame_error, TcpError::command_not_supported);
        out_size_pending_ = w.size();
        return false;
    }
    // Reserve the envelope header, let the dispatcher write the FINS response after it.
    const MutableBytes frame_out{out_.data() + tcp_header_size, max_frame_size};
    const RequestContext context{Link::tcp, std::chrono::system_clock::now()};
    const std::size_t n = dispatcher_.handle(packet.data, frame_out, context);
    if (n > 0) {
        write_tcp_header(w, TcpCommand::frame, n);
        out_size_pending_ = tcp_header_size + n;
    }
    return true;
}

void TcpSession::send_and_continue(std::size_t size, bool close_after) {
    auto self = shared_from_this();
    // One write per response: clients that read one response per recv() depend on it.
    asio::async_write(socket_, asio::buffer(out_.data(), size),
                      [self, close_after](std::error_code ec, std::size_t) {
                          if (ec || close_after) {
                              self->close();
                              return;
                          }
                          self->process();
                      });
}

}  // namespace fins::server
