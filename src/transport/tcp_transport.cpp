#include "transport/tcp_transport.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

#include <boost/asio/connect.hpp>
#include <boost/asio/write.hpp>

#include "transport/asio.hpp"

namespace fins::transport {

using asio::ip::tcp;

namespace {

boost::system::error_code tcp_error_code(std::uint32_t raw) {
    return make_error_code(static_cast<TcpError>(static_cast<int>(raw & 0x7FFFFFFF)));
}

}  // namespace

TcpTransport::TcpTransport(asio::io_context& io, TransportOptions options)
    : SocketTransport(io, std::move(options)) {}

TcpTransport::~TcpTransport() {
    close();
}

void TcpTransport::async_open(OpenHandler done) {
    begin_open(std::move(done), [this](const Resolved& results) {
        auto gen = generation_;
        std::weak_ptr<int> life = life_;
        asio::async_connect(socket_, results,
                            [this, life, gen](boost::system::error_code ec, const tcp::endpoint&) {
                                if (life.expired() || gen != generation_) return;
                                if (ec) return finish_open(Unexpected(ec));
                                on_connected();
                            });
    });
}

void TcpTransport::on_connected() {
    boost::system::error_code ec;
    fd_ = socket_.native_handle();
    socket_.set_option(tcp::no_delay(true), ec);
    if (!ec) set_keepalive(ec);
    if (!ec) socket_.non_blocking(true, ec);
    if (ec) return finish_open(Unexpected(ec));
    ByteWriter w(hello_);
    write_node_address_request(w, options_.requested_node);
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    asio::async_write(socket_, asio::buffer(hello_.data(), w.size()),
                      [this, life, gen](boost::system::error_code ec2, std::size_t) {
                          if (life.expired() || gen != generation_) return;
                          if (ec2) return finish_open(Unexpected(ec2));
                          read_handshake();
                      });
}

void TcpTransport::read_handshake() {
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    socket_.async_read_some(
        asio::buffer(rx_.data() + rx_size_, rx_.size() - rx_size_),
        [this, life, gen](boost::system::error_code ec, std::size_t n) {
            if (life.expired() || gen != generation_) return;
            // The server closes right after an error answer; EOF before it is a failure.
            if (ec) return finish_open(Unexpected(make_error_code(ClientError::handshake_failed)));
            ++reads_;
            rx_size_ += n;
            auto parsed = parse_tcp_frame(Bytes{rx_.data(), rx_size_});
            if (parsed.status == TcpParse::Status::need_more) return read_handshake();
            if (parsed.status == TcpParse::Status::error)
                return finish_open(Unexpected(make_error_code(parsed.error)));
            const auto& packet = parsed.packet;
            if (packet.error != 0 &&
                (packet.command == static_cast<std::uint32_t>(TcpCommand::node_address_response) ||
                 packet.command == static_cast<std::uint32_t>(TcpCommand::frame_error)))
                return finish_open(Unexpected(tcp_error_code(packet.error)));
            if (packet.command != static_cast<std::uint32_t>(TcpCommand::node_address_response))
                return finish_open(Unexpected(make_error_code(ClientError::handshake_failed)));
            auto nodes = decode_node_address_response(packet.data);
            if (!nodes)
                return finish_open(Unexpected(make_error_code(ClientError::handshake_failed)));
            consume(parsed.consumed);
            finish_open(LinkInfo{nodes->client_node, nodes->server_node});
        });
}

void TcpTransport::finish_open(Result<LinkInfo> result) {
    auto done = take_open_handler();
    if (!result) {
        close();
        if (done) done(std::move(result));
        return;
    }
    state_ = State::open;
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    if (done) done(std::move(result));
    if (life.expired() || gen != generation_) return;
    // Frames the server sent right behind its handshake answer are already buffered.
    if (process_frames()) read_frames();
}

void TcpTransport::read_frames() {
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    socket_.async_read_some(asio::buffer(rx_.data() + rx_size_, rx_.size() - rx_size_),
                            [this, life, gen](boost::system::error_code ec, std::size_t n) {
                                if (life.expired() || gen != generation_) return;
                                if (ec)
                                    return fail(make_error_code(ClientError::connection_closed));
                                ++reads_;
                                rx_size_ += n;
                                if (process_frames()) read_frames();
                            });
}

bool TcpTransport::process_frames() {
    std::weak_ptr<int> life = life_;
    auto gen = generation_;
    // Walks the packets with an offset and moves the leftover to the front once, at the
    // end (moving it after every packet costs a copy of the buffer per answer).
    std::size_t pos = 0;
    corked_ = true;
    // Each pass consumes at least one whole packet or stops, so this ends.
    while (pos < rx_size_) {
        auto parsed = parse_tcp_frame(Bytes{rx_.data() + pos, rx_size_ - pos});
        if (parsed.status == TcpParse::Status::need_more) break;
        if (parsed.status == TcpParse::Status::error) {
            send_error_and_fail(parsed.error);
            return false;
        }
        switch (static_cast<TcpCommand>(parsed.packet.command)) {
            case TcpCommand::frame:
                if (on_frame_) on_frame_(parsed.packet.data);
                if (life.expired() || gen != generation_) return false;
                break;
            case TcpCommand::connection_confirmation:
                break;
            case TcpCommand::frame_error:
                fail(tcp_error_code(parsed.packet.error));
                return false;
            default:
                send_error_and_fail(TcpError::command_not_supported);
                return false;
        }
        pos += parsed.consumed;
    }
    consume(pos);
    uncork();
    return life.expired() ? false : gen == generation_;
}

void TcpTransport::uncork() {
    corked_ = false;
    if (cork_.empty()) return;
    write_raw(Bytes{cork_.data(), cork_.size()}, {});
    cork_.clear();
}

bool TcpTransport::peer_gone() {
    if (state_ != State::open) return false;
    // Waiting data is the reader's (and so is a close after it).
    const auto p = os::peek(fd_);
    return p == os::Peek::closed || p == os::Peek::failed;
}

void TcpTransport::consume(std::size_t n) noexcept {
    if (n >= rx_size_) {
        rx_size_ = 0;
        return;
    }
    std::memmove(rx_.data(), rx_.data() + n, rx_size_ - n);
    rx_size_ -= n;
}

void TcpTransport::send_error_and_fail(TcpError error) {
    std::array<std::uint8_t, tcp_header_size> packet{};
    ByteWriter w(packet);
    write_tcp_error(w, TcpCommand::frame_error, error);
    // Best effort, non-blocking: the connection is closed right after anyway.
    boost::system::error_code ignored;
    socket_.send(asio::buffer(packet.data(), w.size()), 0, ignored);
    fail(make_error_code(error));
}

void TcpTransport::send(Bytes frame) {
    if (state_ != State::open) return;
    std::array<std::uint8_t, tcp_header_size> header{};
    ByteWriter w(header);
    write_tcp_header(w, TcpCommand::frame, frame.size());
    if (corked_) {
        cork_.insert(cork_.end(), header.begin(),
                     header.begin() + static_cast<std::ptrdiff_t>(w.size()));
        cork_.insert(cork_.end(), frame.begin(), frame.end());
        return;
    }
    write_raw(Bytes{header.data(), w.size()}, frame);
}

void TcpTransport::write_raw(Bytes first, Bytes second) {
    if (writing_) {
        queue_.push(first, second);
        return;
    }
    // Nothing queued: hand the packet to the kernel now; queue only what did not fit.
    std::array<asio::const_buffer, 2> buffers{asio::buffer(first.data(), first.size()),
                                              asio::buffer(second.data(), second.size())};
    boost::system::error_code ec;
    auto written = socket_.send(buffers, 0, ec);
    if (!ec && written == first.size() + second.size()) return;
    // would_block, or a real error that the queued write reports asynchronously (never
    // from inside send(): the caller may be the request tracker).
    queue_.push(first, second);
    front_written_ = ec ? 0 : written;
    write_next();
}

void TcpTransport::write_next() {
    if (writing_ || queue_.empty()) return;
    writing_ = true;
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    const auto& buffer = queue_.front();
    asio::async_write(socket_,
                      asio::buffer(buffer.data() + front_written_, buffer.size() - front_written_),
                      [this, life, gen](boost::system::error_code ec, std::size_t) {
                          if (life.expired() || gen != generation_) return;
                          writing_ = false;
                          front_written_ = 0;
                          if (ec) return fail(make_error_code(ClientError::connection_closed));
                          queue_.pop();
                          write_next();
                      });
}

void TcpTransport::set_keepalive(boost::system::error_code& ec) {
    const auto& k = options_.keepalive;
    if (k.idle.count() <= 0) return;
    os::KeepAliveTiming timing;
    timing.idle = k.idle;
    timing.interval = std::max(k.interval, std::chrono::seconds(1));
    timing.probes = std::max(k.count, 1);
    // Unacknowledged data fails the connection when the probes would have.
    timing.user_timeout = timing.idle + timing.interval * timing.probes;
    ec = os::set_keepalive(fd_, timing);
}

void TcpTransport::close() {
    close_connection();
    fd_ = os::invalid_socket;
    front_written_ = 0;
    rx_size_ = 0;
    corked_ = false;
    cork_.clear();
}

}  // namespace fins::transport
