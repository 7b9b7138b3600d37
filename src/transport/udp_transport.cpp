#include "transport/udp_transport.hpp"

#ifdef __linux__
#include <sys/socket.h>
#include <sys/uio.h>
#endif

#include <algorithm>
#include <array>
#include <cerrno>
#include <string>
#include <utility>

#include <boost/asio/connect.hpp>

#include "transport/asio.hpp"
#include "transport/socket_os.hpp"

namespace fins::transport {

using asio::ip::udp;

UdpTransport::UdpTransport(asio::io_context& io, TransportOptions options)
    : SocketTransport(io, std::move(options)) {}

UdpTransport::~UdpTransport() {
    close();
}

void UdpTransport::async_open(OpenHandler done) {
    begin_open(std::move(done), [this](const Resolved& results) { connect_first(results); });
}

void UdpTransport::connect_first(const udp::resolver::results_type& results) {
    boost::system::error_code ec = asio::error::host_not_found;
    for (const auto& entry : results) {
        boost::system::error_code ignored;
        socket_.close(ignored);
        ec.clear();
        socket_.open(entry.endpoint().protocol(), ec);
        if (!ec) socket_.connect(entry.endpoint(), ec);
        if (!ec) break;
    }
    if (!ec) socket_.non_blocking(true, ec);
    if (!ec) {
        // Best effort: the kernel caps it at net.core.rmem_max.
        boost::system::error_code ignored;
        socket_.set_option(asio::socket_base::receive_buffer_size(udp_receive_buffer), ignored);
    }
    LinkInfo info;
    if (!ec) {
        auto local = socket_.local_endpoint(ec);
        auto remote = socket_.remote_endpoint(ec);
        if (!ec) {
            info.local_node = node_from_address(local.address());
            info.remote_node = node_from_address(remote.address());
        }
    }
    if (ec) return finish_open(Unexpected(ec));
    finish_open(info);
}

void UdpTransport::finish_open(Result<LinkInfo> result) {
    auto done = take_open_handler();
    if (result) {
        state_ = State::open;
        receive();
    } else {
        close();
    }
    if (done) done(std::move(result));
}

ReceiveError classify_receive_error(boost::system::error_code ec) noexcept {
    if (ec == asio::error::connection_refused) return ReceiveError::nothing_listening;
#ifdef _WIN32
    // An ICMP port unreachable: WSAECONNRESET from a synchronous receive, and from an
    // overlapped one ERROR_PORT_UNREACHABLE (Windows) or ERROR_CONNECTION_REFUSED (Wine).
    const auto win32 = [&](DWORD code) {
        return ec ==
               boost::system::error_code(static_cast<int>(code), boost::system::system_category());
    };
    if (ec == asio::error::connection_reset || win32(ERROR_PORT_UNREACHABLE) ||
        win32(ERROR_CONNECTION_REFUSED))
        return ReceiveError::nothing_listening;
    const bool host_down =
        ec == boost::system::error_code(WSAEHOSTDOWN, boost::system::system_category());
#else
    const bool host_down =
        ec == boost::system::error_code(EHOSTDOWN, boost::system::system_category()) ||
        ec == boost::system::error_code(ENONET, boost::system::system_category());
#endif
    if (host_down || ec == asio::error::host_unreachable ||
        ec == asio::error::network_unreachable || ec == asio::error::network_down ||
        ec == asio::error::connection_reset || ec == asio::error::timed_out ||
        ec == std::errc::protocol_error || ec == std::errc::message_size ||
        ec == asio::error::interrupted)
        return ReceiveError::transient;
    return ReceiveError::fatal;
}

#ifdef __linux__
namespace {

// recvmmsg's buffers, shared by the thread's UDP transports (see udp_transport.hpp).
struct ReceiveBatch {
    static constexpr unsigned size = 16;
    std::array<std::array<std::uint8_t, max_frame_size + 1>, size> buffers;
    std::array<mmsghdr, size> messages;
    std::array<iovec, size> vectors;
    bool busy = false;
};

ReceiveBatch& receive_batch() {
    thread_local ReceiveBatch batch{};
    return batch;
}

boost::system::error_code last_error() {
    return {errno, boost::system::system_category()};
}

}  // namespace

void UdpTransport::receive() {
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    socket_.async_wait(udp::socket::wait_read, [this, life, gen](boost::system::error_code ec) {
        if (life.expired() || gen != generation_) return;
        if (ec && !on_receive(ec, {})) return;
        // Frames the handlers send meanwhile leave together once every answer is read.
        holding_ = true;
        if (!drain()) return;
        holding_ = false;
        flush();
        receive();
    });
}

bool UdpTransport::drain() {
    auto& batch = receive_batch();
    const bool shared = !batch.busy;
    batch.busy = true;
    struct Release {
        ReceiveBatch& batch;
        bool shared;
        ~Release() {
            if (shared) batch.busy = false;
        }
    } release{batch, shared};
    const unsigned size = shared ? ReceiveBatch::size : 1;
    // Bounded, so that one busy socket cannot hold the others up: 64 datagrams, then the
    // reactor again.
    for (int round = 0; round < 4; ++round) {
        for (unsigned i = 0; i < size; ++i) {
            batch.vectors[i] = {shared ? batch.buffers[i].data() : rx_.data(), rx_size};
            batch.messages[i] = {};
            batch.messages[i].msg_hdr.msg_iov = &batch.vectors[i];
            batch.messages[i].msg_hdr.msg_iovlen = 1;
        }
        const int n =
            ::recvmmsg(socket_.native_handle(), batch.messages.data(), size, MSG_DONTWAIT, nullptr);
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK) {
                read_to_end_ = true;
                return true;
            }
            if (!on_receive(last_error(), {})) return false;
            continue;
        }
        for (int i = 0; i < n; ++i) {
            const auto& m = batch.messages[static_cast<std::size_t>(i)];
            const auto* data = static_cast<const std::uint8_t*>(m.msg_hdr.msg_iov->iov_base);
            if (!on_receive({}, Bytes{data, m.msg_len})) return false;
        }
        if (static_cast<unsigned>(n) < size) {
            // Fewer than asked for: the queue was empty (an error after the datagrams
            // would stay pending and wake the reactor again).
            read_to_end_ = true;
            return true;
        }
    }
    return true;
}

void UdpTransport::flush() {
    if (!held_sizes_.empty()) read_to_end_ = false;
    constexpr std::size_t most = 32;
    std::array<mmsghdr, most> messages;
    std::array<iovec, most> vectors;
    std::size_t next = 0, offset = 0;
    while (next < held_sizes_.size()) {
        const auto count = std::min(most, held_sizes_.size() - next);
        std::size_t at = offset;
        for (std::size_t i = 0; i < count; ++i) {
            vectors[i] = {held_.data() + at, held_sizes_[next + i]};
            messages[i] = {};
            messages[i].msg_hdr.msg_iov = &vectors[i];
            messages[i].msg_hdr.msg_iovlen = 1;
            at += held_sizes_[next + i];
        }
        const int sent = ::sendmmsg(socket_.native_handle(), messages.data(),
                                    static_cast<unsigned>(count), MSG_DONTWAIT | MSG_NOSIGNAL);
        if (sent < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
            // That datagram is lost: the retry logic's business, as for send().
            offset += held_sizes_[next++];
            continue;
        }
        if (sent <= 0) {
            // The socket's buffer is full: the rest waits in the queue, in order.
            for (; next < held_sizes_.size(); offset += held_sizes_[next++])
                queue_.push(Bytes{held_.data() + offset, held_sizes_[next]});
            write_next();
            break;
        }
        for (int i = 0; i < sent; ++i)
            offset += held_sizes_[next++];
    }
    held_.clear();
    held_sizes_.clear();
}
#else
void UdpTransport::receive() {
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    socket_.async_receive(asio::buffer(rx_),
                          [this, life, gen](boost::system::error_code ec, std::size_t n) {
                              if (life.expired() || gen != generation_) return;
                              if (!on_receive(ec, ec ? Bytes{} : Bytes{rx_.data(), n})) return;
                              if (!drain()) return;
                              receive();
                          });
}

bool UdpTransport::drain() {
    // Takes what else is queued now, without another trip through the reactor.
    for (int i = 0; i < 64; ++i) {
        boost::system::error_code e;
        const auto m = socket_.receive(asio::buffer(rx_), 0, e);
        if (e == asio::error::would_block || e == asio::error::try_again) break;
        if (!on_receive(e, e ? Bytes{} : Bytes{rx_.data(), m})) return false;
    }
    return true;
}

void UdpTransport::flush() {}  // nothing is held: send() writes at once
#endif

bool UdpTransport::on_receive(boost::system::error_code ec, Bytes datagram) {
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    if (ec) {
        switch (classify_receive_error(ec)) {
            case ReceiveError::nothing_listening:
                // One code on every system (include/fins/client.hpp): Windows says
                // WSAECONNRESET, ERROR_PORT_UNREACHABLE or (Wine) ERROR_CONNECTION_REFUSED.
                if (on_error_) on_error_(make_error_code(asio::error::connection_refused));
                break;
            case ReceiveError::transient:
                break;
            case ReceiveError::fatal:
                fail(make_error_code(ClientError::connection_closed));
                return false;
        }
    } else if (datagram.size() < rx_size && on_frame_) {
        // A datagram that fills the whole buffer is longer than 2,012 bytes: not FINS.
        on_frame_(datagram);
    }
    return !life.expired() && gen == generation_;
}

bool UdpTransport::peer_gone() {
    if (state_ != State::open) return false;
    // Reading SO_ERROR clears an ICMP error left by earlier traffic, so it cannot fail
    // the request about to be sent.
    os::clear_pending_error(socket_.native_handle());
    return false;
}

void UdpTransport::send(Bytes frame) {
    if (state_ != State::open) return;
    read_to_end_ = false;
    if (holding_ && !writing_ && queue_.empty()) {
        held_.insert(held_.end(), frame.begin(), frame.end());
        held_sizes_.push_back(frame.size());
        return;
    }
    if (!writing_ && queue_.empty()) {
        boost::system::error_code ec;
        socket_.send(asio::buffer(frame.data(), frame.size()), 0, ec);
        // Lost datagrams are the retry logic's business; only a full buffer is queued.
        if (ec != asio::error::would_block && ec != asio::error::try_again) return;
    }
    queue_.push(frame);
    write_next();
}

void UdpTransport::write_next() {
    if (writing_ || queue_.empty()) return;
    writing_ = true;
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    const auto& buffer = queue_.front();
    socket_.async_send(asio::buffer(buffer),
                       [this, life, gen](boost::system::error_code, std::size_t) {
                           if (life.expired() || gen != generation_) return;
                           writing_ = false;
                           queue_.pop();
                           write_next();
                       });
}

void UdpTransport::close() {
    close_connection();
    read_to_end_ = false;
    holding_ = false;
    held_.clear();
    held_sizes_.clear();
}

}  // namespace fins::transport
