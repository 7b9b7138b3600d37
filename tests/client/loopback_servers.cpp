#include "client/loopback_servers.hpp"

#include <algorithm>
#include <deque>

#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>

#include "fins/tcp.hpp"
#include "transport/asio.hpp"

namespace fins::test {

// ---- ServerBase ----

ServerBase::ServerBase() = default;
ServerBase::~ServerBase() {
    stop_thread();
}

void ServerBase::start_thread() {
    thread_ = std::thread([this] {
        auto guard = asio::make_work_guard(io_);
        io_.run();
    });
}

void ServerBase::stop_thread() {
    io_.stop();
    if (thread_.joinable()) thread_.join();
}

std::vector<std::vector<std::uint8_t>> ServerBase::requests() {
    std::lock_guard lock(mutex_);
    return requests_;
}

bool ServerBase::wait_for_requests(std::size_t n, std::chrono::milliseconds limit) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, limit, [&] { return requests_.size() >= n; });
}

void ServerBase::with_plc(const std::function<void(FakePlc&)>& f) {
    std::lock_guard lock(mutex_);
    f(plc_);
}

std::vector<std::uint8_t> ServerBase::record_and_handle(Bytes frame) {
    std::lock_guard lock(mutex_);
    requests_.emplace_back(frame.begin(), frame.end());
    changed_.notify_all();
    return plc_.handle(frame);
}

// ---- UdpResponder ----

UdpResponder::UdpResponder(const std::string& address) : socket_(io_) {
    boost::system::error_code ec;
    auto ip = asio::ip::make_address(address, ec);
    if (!ec) socket_.open(ip.is_v4() ? asio::ip::udp::v4() : asio::ip::udp::v6(), ec);
    if (!ec) socket_.bind({ip, 0}, ec);
    if (ec) return;
    // Bursts of 256 requests must all arrive: the tests lose only what they mean to.
    socket_.set_option(asio::socket_base::receive_buffer_size(1 << 21), ec);
    port_ = socket_.local_endpoint().port();
    ok_ = true;
    receive();
    start_thread();
}

UdpResponder::~UdpResponder() {
    stop_thread();
}

void UdpResponder::hold_until(std::size_t n) {
    std::lock_guard lock(mutex_);
    hold_ = n;
}
void UdpResponder::set_silent(bool silent) {
    std::lock_guard lock(mutex_);
    silent_ = silent;
}
void UdpResponder::set_duplicate(bool duplicate) {
    std::lock_guard lock(mutex_);
    duplicate_ = duplicate;
}

void UdpResponder::receive() {
    socket_.async_receive_from(asio::buffer(buffer_), peer_,
                               [this](boost::system::error_code ec, std::size_t n) {
                                   if (ec) return;
                                   auto answer = record_and_handle(Bytes{buffer_.data(), n});
                                   std::vector<std::vector<std::uint8_t>> out;
                                   bool twice = false;
                                   {
                                       std::lock_guard lock(mutex_);
                                       twice = duplicate_;
                                       if (!silent_ && !answer.empty()) {
                                           held_.push_back(std::move(answer));
                                           if (held_.size() >= std::max<std::size_t>(hold_, 1)) {
                                               out.assign(held_.rbegin(), held_.rend());
                                               held_.clear();
                                           }
                                       }
                                   }
                                   for (const auto& frame : out) {
                                       boost::system::error_code ignored;
                                       socket_.send_to(asio::buffer(frame), peer_, 0, ignored);
                                       if (twice)
                                           socket_.send_to(asio::buffer(frame), peer_, 0, ignored);
                                   }
                                   if (!out.empty()) {
                                       std::lock_guard lock(mutex_);
                                       answers_sent_ += out.size();
                                       changed_.notify_all();
                                   }
                                   receive();
                               });
}

bool UdpResponder::wait_for_answers(std::size_t n, std::chrono::milliseconds limit) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, limit, [&] { return answers_sent_ >= n; });
}

// ---- TcpResponder ----

struct TcpResponder::Session : std::enable_shared_from_this<Session> {
    Session(TcpResponder& s, asio::ip::tcp::socket sock) : server(s), socket(std::move(sock)) {
        socket.set_option(asio::ip::tcp::no_delay(true));
    }

    void read() {
        auto self = shared_from_this();
        socket.async_read_some(asio::buffer(rx.data() + rx_size, rx.size() - rx_size),
                               [self](boost::system::error_code ec, std::size_t n) {
                                   if (ec) return;
                                   self->rx_size += n;
                                   if (self->process()) self->read();
                               });
    }

    // Handles every complete packet; false once the session is closing.
    bool process() {
        for (int guard = 0; guard < 1000; ++guard) {
            auto p = parse_tcp_frame(Bytes{rx.data(), rx_size});
            if (p.status != TcpParse::Status::packet)
                return p.status == TcpParse::Status::need_more;
            bool keep = handle(p.packet);
            std::copy(rx.begin() + static_cast<std::ptrdiff_t>(p.consumed),
                      rx.begin() + static_cast<std::ptrdiff_t>(rx_size), rx.begin());
            rx_size -= p.consumed;
            if (!keep) return false;
        }
        return false;
    }

    bool handle(const TcpPacket& packet) {
        using Mode = TcpBehaviour::Mode;
        auto& b = server.behaviour_;
        std::vector<std::uint8_t> out(tcp_max_packet);
        ByteWriter w(out);
        if (b.mode == Mode::mute) return true;
        if (packet.command == static_cast<std::uint32_t>(TcpCommand::node_address_request)) {
            auto requested = decode_node_address_request(packet.data).value_or(0);
            {
                std::lock_guard lock(server.mutex_);
                server.handshakes_.push_back(requested);
                server.changed_.notify_all();
            }
            if (b.mode == Mode::handshake_error) {
                write_node_address_response(w, requested, b.server_node, b.error);
                send(w, 0, true);
                return false;
            }
            write_node_address_response(w, requested ? requested : b.allocated_node, b.server_node);
            send(w, 0, false);
            return true;
        }
        if (packet.command == static_cast<std::uint32_t>(TcpCommand::frame_error)) {
            std::lock_guard lock(server.mutex_);
            server.envelope_errors_.push_back(packet.error);
            server.changed_.notify_all();
            return false;
        }
        auto answer = server.record_and_handle(packet.data);
        if (b.mode == Mode::unknown_command && !server.dropped_) {
            server.dropped_ = true;
            write_tcp_header(w, static_cast<TcpCommand>(0x99), 0);
            send(w, 0, false);
            return true;
        }
        if ((b.mode == Mode::drop_first || b.mode == Mode::frame_error) && !server.dropped_) {
            server.dropped_ = true;
            if (b.mode == Mode::drop_first) {
                socket.close();
                return false;
            }
            write_tcp_error(w, TcpCommand::frame_error, TcpError::command_not_supported);
            send(w, 0, true);
            return false;
        }
        if (answer.empty()) return true;
        if (b.mode == Mode::confirm) write_tcp_header(w, TcpCommand::connection_confirmation, 0);
        write_tcp_header(w, TcpCommand::frame, answer.size());
        w.bytes(answer);
        if (b.mode == Mode::split) {
            std::size_t at = 0;
            {
                std::lock_guard lock(server.mutex_);
                at = server.next_split_;
                server.next_split_ = at + 1 < w.size() ? at + 1 : 1;
                ++server.split_answers_;
            }
            send(w, at, false);
        } else if (b.mode == Mode::glue) {
            glued.insert(glued.end(), out.begin(),
                         out.begin() + static_cast<std::ptrdiff_t>(w.size()));
            if (++glued_count == 2) {
                queue.push_back(std::move(glued));
                glued.clear();
                glued_count = 0;
                write_next();
            }
        } else {
            send(w, 0, false);
        }
        return true;
    }

    // Queues what `w` holds, as two writes when split_at > 0.
    void send(const ByteWriter& w, std::size_t split_at, bool close_after) {
        auto bytes = w.written();
        if (split_at > 0 && split_at < bytes.size()) {
            queue.emplace_back(bytes.begin(),
                               bytes.begin() + static_cast<std::ptrdiff_t>(split_at));
            queue.emplace_back(bytes.begin() + static_cast<std::ptrdiff_t>(split_at), bytes.end());
        } else {
            queue.emplace_back(bytes.begin(), bytes.end());
        }
        closing = closing || close_after;
        write_next();
    }

    void write_next() {
        if (writing) return;
        if (queue.empty()) {
            if (closing) socket.close();
            return;
        }
        writing = true;
        auto self = shared_from_this();
        asio::async_write(socket, asio::buffer(queue.front()),
                          [self](boost::system::error_code ec, std::size_t) {
                              self->writing = false;
                              self->queue.pop_front();
                              if (ec) return;
                              self->write_next();
                          });
    }

    TcpResponder& server;
    asio::ip::tcp::socket socket;
    std::array<std::uint8_t, 2 * tcp_max_packet> rx{};
    std::size_t rx_size = 0;
    std::deque<std::vector<std::uint8_t>> queue;
    std::vector<std::uint8_t> glued;
    int glued_count = 0;
    bool writing = false;
    bool closing = false;
};

TcpResponder::TcpResponder(TcpBehaviour behaviour, const std::string& address)
    : behaviour_(behaviour), acceptor_(io_) {
    boost::system::error_code ec;
    auto ip = asio::ip::make_address(address, ec);
    if (!ec) acceptor_.open(ip.is_v4() ? asio::ip::tcp::v4() : asio::ip::tcp::v6(), ec);
    if (!ec) acceptor_.bind({ip, 0}, ec);
    if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
    if (ec) return;
    port_ = acceptor_.local_endpoint().port();
    ok_ = true;
    accept();
    start_thread();
}

TcpResponder::~TcpResponder() {
    stop_thread();
    sessions_.clear();
}

void TcpResponder::accept() {
    acceptor_.async_accept([this](boost::system::error_code ec, asio::ip::tcp::socket socket) {
        if (ec) return;
        auto session = std::make_shared<Session>(*this, std::move(socket));
        sessions_.push_back(session);
        session->read();
        accept();
    });
}

std::vector<std::uint8_t> TcpResponder::handshakes() {
    std::lock_guard lock(mutex_);
    return handshakes_;
}

std::vector<std::uint32_t> TcpResponder::envelope_errors(std::size_t n,
                                                         std::chrono::milliseconds limit) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, limit, [&] { return envelope_errors_.size() >= n; });
    return envelope_errors_;
}

bool TcpResponder::drop_connections(std::chrono::milliseconds limit) {
    bool done = false;
    asio::post(io_, [this, &done] {
        for (auto& session : sessions_) {
            boost::system::error_code ignored;
            session->socket.close(ignored);
        }
        std::lock_guard lock(mutex_);
        done = true;
        changed_.notify_all();
    });
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, limit, [&] { return done; });
}

std::size_t TcpResponder::split_answers() {
    std::lock_guard lock(mutex_);
    return split_answers_;
}

}  // namespace fins::test
