// ControlServer: finsd's run-time control channel (contract in control.hpp).
//
// Protocol: one JSON object per line in, one JSON object per line out, in order. The
// verbs are control_requests.hpp's and control_instructions.hpp's; any request may name
// its CPU Unit with "plc". A send / recv / sendcmd answers when the instruction
// completes (the next line is read only then, so answers stay in request order).
// Anything else answers {"error":"..."} and the connection stays open. A line longer
// than max_line_size answers an error and closes the connection. Every handler runs on
// the server's io_context, so a Plc is touched by one thread only. One Session serves
// both transports (a generic stream socket); on the loopback one it first reads the token
// line (control_channel_file.hpp): a wrong or overlong one closes the connection unanswered.
#include "server/control/control.hpp"
#include "server/instructions/instruction_schedule.hpp"

#ifndef _WIN32
#include <sys/stat.h>
#endif

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>
#include <boost/asio/generic/stream_protocol.hpp>
#ifndef _WIN32
#include <boost/asio/local/stream_protocol.hpp>
#endif
#include <boost/asio/read_until.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/write.hpp>
#include <nlohmann/json.hpp>

#include "server/control/control_channel_file.hpp"
#include "server/control/control_dispatch.hpp"
#include "server/control/control_requests.hpp"
#include "server/sessions/failure_boundary.hpp"
#include "transport/asio.hpp"

namespace fins::server {

namespace {

using Json = nlohmann::json;
using stream = asio::generic::stream_protocol;
using Clock = std::chrono::steady_clock;

// A SendCmd of 2,002 bytes is 4,004 hex digits plus its keys: room for it.
constexpr std::size_t max_line_size = 8192;

struct Shared {
    std::vector<ControlTarget> targets;
    ControlOptions options;
    bool stopped = false;
};

// Compares every character whatever the first difference, so the time taken does not
// tell a guesser how much of the token was right.
bool same_token(const std::string& line, const std::string& token) {
    if (line.size() != token.size()) return false;
    unsigned char differ = 0;
    for (std::size_t i = 0; i < token.size(); ++i)
        differ = static_cast<unsigned char>(differ | (line[i] ^ token[i]));
    return differ == 0;
}

class Session : public std::enable_shared_from_this<Session> {
  public:
    Session(stream::socket socket, std::shared_ptr<Shared> shared)
        : socket_(std::move(socket)),
          timer_(socket_.get_executor()),
          buffer_(max_line_size),
          shared_(std::move(shared)),
          authenticated_(shared_->options.token.empty()) {}

    void start() { read(); }
    void close() {
        boost::system::error_code ignored;
        open_ = false;
        timer_.cancel();
        socket_.close(ignored);
    }
    [[nodiscard]] bool open() const noexcept { return open_; }
    // Waiting for an instruction's answer: holds no slot.
    [[nodiscard]] bool waiting() const noexcept { return waiting_; }
    [[nodiscard]] Clock::time_point last_activity() const noexcept { return last_activity_; }
    // Loopback: has sent the token (a Unix socket's clients always have).
    [[nodiscard]] bool authenticated() const noexcept { return authenticated_; }

  private:
    void read() {
        last_activity_ = Clock::now();
        arm_idle_timer();
        asio::async_read_until(
            socket_, buffer_, '\n',
            [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
                self->guarded([&] { self->on_line(ec, n); });
            });
    }

    void arm_idle_timer() {
        const auto idle = shared_->options.idle_timeout;
        if (idle.count() <= 0) return;
        timer_.expires_after(idle);
        timer_.async_wait(
            [self = shared_from_this(), generation = ++generation_](boost::system::error_code ec) {
                if (ec || generation != self->generation_ || self->waiting_) return;
                self->close();
            });
    }

    // The failure boundary of a connection's own work (reading a line, parsing it,
    // writing an answer; a request's verb has its own in dispatch_control_request):
    // what throws is counted and logged, and closes this connection only.
    template <class F>
    void guarded(F&& f) noexcept {
        try {
            f();
        } catch (...) {
            std::string what = "an exception";
            try {
                what = describe_exception(std::current_exception());
            } catch (...) {
                // No memory for the text.
            }
            note_failure(FailureChannel::control, "a control connection", what);
            try {
                close();
            } catch (...) {
                // The socket goes with the session.
            }
        }
    }

    void on_line(boost::system::error_code ec, std::size_t n) {
        ++generation_;  // a line (or the end) came: the idle timer is moot
        timer_.cancel();
        last_activity_ = Clock::now();
        if (shared_->stopped || !open_) return;
        if (!authenticated_) return on_token(ec, n);
        if (ec == asio::error::not_found) {  // the buffer is full and holds no newline
            return write(
                control_error(fmt::format("request line longer than {} bytes", max_line_size)),
                true);
        }
        if (ec) return close();
        const std::string line = take_line(n);
        serve(line);
    }

    // The n bytes read_until found, without their newline (nor a CR before it).
    std::string take_line(std::size_t n) {
        const auto data = buffer_.data();
        std::string line(asio::buffers_begin(data),
                         asio::buffers_begin(data) + static_cast<std::ptrdiff_t>(n - 1));
        buffer_.consume(n);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        return line;
    }

    // The first line on the loopback channel: the token, or the end without a word.
    void on_token(boost::system::error_code ec, std::size_t n) {
        if (ec) return close();
        const std::string line = take_line(n);
        if (!same_token(line, shared_->options.token)) return close();
        authenticated_ = true;
        read();
    }

    void serve(const std::string& line) {
        const Json j = Json::parse(line, nullptr, false);
        if (j.is_discarded()) return write(control_error("not JSON"), false);
        // Set before: an answer given at once clears it inside the call.
        waiting_ = true;
        dispatch_control_request(shared_->targets, j, [self = shared_from_this()](Json reply) {
            self->waiting_ = false;
            if (self->shared_->stopped || !self->open_) return;
            self->write(std::move(reply), false);
        });
    }

    void write(const Json& reply, bool close_after) {
        reply_ = reply.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
        last_activity_ = Clock::now();
        asio::async_write(
            socket_, asio::buffer(reply_),
            [self = shared_from_this(), close_after](boost::system::error_code ec, std::size_t) {
                if (ec || close_after || self->shared_->stopped) return self->close();
                self->guarded([&] { self->read(); });
            });
    }

    stream::socket socket_;
    asio::steady_timer timer_;
    asio::streambuf buffer_;
    std::shared_ptr<Shared> shared_;
    std::string reply_;
    bool authenticated_;
    bool open_ = true;
    bool waiting_ = false;
    std::uint64_t generation_ = 0;
    Clock::time_point last_activity_ = Clock::now();
};

}  // namespace

struct ControlServer::Impl {
    Impl(asio::io_context& io, std::filesystem::path p) : acceptor(io), path(std::move(p)) {}

    // Every slot taken by a client that waits for a line: the one idle longest goes, one
    // that has not sent the token before any that has (so connections that never send it
    // cannot push out a client that did).
    void make_room() {
        std::erase_if(sessions, [](const auto& w) {
            const auto s = w.lock();
            return s == nullptr || !s->open();
        });
        std::vector<std::shared_ptr<Session>> holding;
        for (const auto& w : sessions)
            if (auto s = w.lock(); s != nullptr && !s->waiting()) holding.push_back(std::move(s));
        if (holding.size() < shared->options.max_connections || holding.empty()) return;
        const auto oldest =
            std::min_element(holding.begin(), holding.end(), [](const auto& a, const auto& b) {
                if (a->authenticated() != b->authenticated()) return !a->authenticated();
                return a->last_activity() < b->last_activity();
            });
        (*oldest)->close();
    }

    void accept() {
        acceptor.async_accept(
            [this, shared = shared](boost::system::error_code ec, stream::socket socket) {
                if (shared->stopped || ec == asio::error::operation_aborted) return;
                if (!ec) {
                    try {
                        make_room();
                        auto session = std::make_shared<Session>(std::move(socket), shared);
                        sessions.push_back(session);
                        session->start();
                    } catch (...) {  // this client is not served; the channel goes on
                        note_failure(FailureChannel::control, "accepting a control connection",
                                     "out of memory or another exception");
                    }
                }
                accept();
            });
    }

    ControlAcceptor acceptor;
    std::filesystem::path path;
    std::shared_ptr<Shared> shared = std::make_shared<Shared>();
    std::vector<std::weak_ptr<Session>> sessions;
};

Result<std::unique_ptr<ControlServer>> ControlServer::start(asio::io_context& io, plc::Plc& plc,
                                                            const std::filesystem::path& path,
                                                            NetworkInstructions* instructions,
                                                            const InstructionSchedule* schedule) {
    ControlTarget target;
    target.plc = &plc;
    target.instructions = instructions;
    for (std::size_t i = 0; schedule != nullptr && i < schedule->size(); ++i)
        target.schedule.push_back({schedule, i});
    return start(io, std::vector<ControlTarget>{std::move(target)}, path);
}

#ifndef _WIN32
namespace {

// A Unix-domain socket at `path`, replacing a stale one (contract in control.hpp).
Result<void> open_unix_channel(asio::io_context& io, ControlAcceptor& acceptor,
                               const std::filesystem::path& path) {
    // sockaddr_un holds at most 107 characters and a terminating NUL.
    constexpr std::size_t max_path = 107;
    const std::string name = path.string();
    if (path.empty() || name.size() > max_path)
        return Unexpected(std::make_error_code(std::errc::filename_too_long));
    boost::system::error_code ec;
    const auto st = std::filesystem::symlink_status(path, ec);
    if (std::filesystem::exists(st)) {
        // Replace a stale socket, never a regular file someone pointed us at by mistake,
        // nor the socket of a finsd that still answers on it.
        if (!std::filesystem::is_socket(st))
            return Unexpected(std::make_error_code(std::errc::file_exists));
        asio::local::stream_protocol::socket probe(io);
        if (probe.connect(asio::local::stream_protocol::endpoint(name), ec); !ec)
            return Unexpected(std::make_error_code(std::errc::address_in_use));
        std::filesystem::remove(path, ec);
    }
    const stream::endpoint endpoint(asio::local::stream_protocol::endpoint{name});
    if (acceptor.open(endpoint.protocol(), ec); ec) return Unexpected(ec);
    if (acceptor.bind(endpoint, ec); ec) return Unexpected(ec);
    ::chmod(path.c_str(), 0600);  // the channel changes the PLC: its owner only
    if (acceptor.listen(asio::socket_base::max_listen_connections, ec); ec) return Unexpected(ec);
    return {};
}

}  // namespace
#endif

Result<std::unique_ptr<ControlServer>> ControlServer::start(asio::io_context& io,
                                                            std::vector<ControlTarget> targets,
                                                            const std::filesystem::path& path,
                                                            ControlOptions options) {
    if (targets.empty() || options.max_connections == 0)
        return Unexpected(std::make_error_code(std::errc::invalid_argument));
    const bool loopback = options.transport == ControlTransport::loopback_tcp;
    // A Unix socket's clients need no token (the socket's mode admits its owner only).
    if (!loopback) options.token.clear();
    auto impl = std::make_unique<Impl>(io, path);
    impl->shared->targets = std::move(targets);
    impl->shared->options = std::move(options);
    const auto& token = impl->shared->options.token;
#ifdef _WIN32
    const auto opened = open_loopback_channel(impl->acceptor, path, token);
#else
    const auto opened = loopback ? open_loopback_channel(impl->acceptor, path, token)
                                 : open_unix_channel(io, impl->acceptor, path);
#endif
    if (!opened) return Unexpected(opened.error());  // (no stop: the path is left alone)
    impl->accept();
    return std::unique_ptr<ControlServer>(new ControlServer(std::move(impl)));
}

ControlServer::ControlServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ControlServer::~ControlServer() {
    stop();
}

void ControlServer::stop() {
    if (!impl_ || impl_->shared->stopped) return;
    impl_->shared->stopped = true;
    boost::system::error_code ec;
    impl_->acceptor.close(ec);
    for (auto& w : impl_->sessions)
        if (auto s = w.lock()) s->close();
    impl_->sessions.clear();
    std::filesystem::remove(impl_->path, ec);
}

}  // namespace fins::server
