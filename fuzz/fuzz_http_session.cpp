// Fuzzes finsd's whole HTTP session (src/web/http_session.cpp, and after an upgrade
// websocket_session.cpp) with its real code on one io_context: the input is what a
// client sends, over a socketpair, in pieces of the size its first byte names (so the
// parser sees requests split anywhere), then the client shuts its sending side. Chunked
// bodies and trailers, the limits, pipelined requests, an upgrade to /ws and the
// WebSocket frames after it all run as in finsd (control on: writes reach the virtual
// PLC). What comes back must be HTTP (it starts with "HTTP/1.1 "); an exception out of
// the session, a crash or a hang traps. The handlers run with io_context::poll only, so
// timers (deadlines, ticks, pings) never fire and every run is bounded.
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "plc/plc.hpp"
#include "web/sessions.hpp"

namespace {

namespace asio = boost::asio;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

struct State {
    State() {
        fins::server::ControlTarget t;
        t.plc = &plc;
        t.addresses = {{0, 1}};
        context.targets.push_back(t);
        context.options.control = true;
        context.options.port = 8080;
    }
    fins::plc::Plc plc;
    fins::web::WebContext context;
};

// Reads what the server sent so far (non-blocking) into `out`.
void drain(int fd, std::string& out) {
    char buffer[4096];
    for (int i = 0; i < 1000; ++i) {
        const auto n = ::read(fd, buffer, sizeof buffer);
        if (n <= 0) return;
        if (out.size() < 64) out.append(buffer, static_cast<std::size_t>(n));
    }
}

void run(asio::io_context& io, int client, std::string& out) {
    for (int i = 0; i < 200; ++i) {
        const auto ran = io.poll();
        drain(client, out);
        if (ran == 0) return;
        io.restart();
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static State state;
    if (size == 0) return 0;
    const std::size_t piece = data[0] == 0 ? size : data[0];
    ++data;
    --size;

    int fds[2];
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds) != 0) return 0;
    const int client = fds[1];
    std::string out;
    {
        asio::io_context io;
        auto shared = std::make_shared<fins::web::ServerShared>(io, state.context);
        {
            asio::ip::tcp::socket socket(io);
            boost::system::error_code ec;
            socket.assign(asio::ip::tcp::v4(), fds[0], ec);
            check(!ec);
            fins::web::run_http_session(std::move(socket), shared);
        }
        std::size_t sent = 0;
        for (int rounds = 0; sent < size && rounds < 10000; ++rounds) {
            const std::size_t n = std::min(piece, size - sent);
            const auto w = ::send(client, data + sent, n, MSG_NOSIGNAL);  // no SIGPIPE
            if (w > 0) sent += static_cast<std::size_t>(w);
            if (w < 0 && errno != EAGAIN) break;  // the server closed
            run(io, client, out);
        }
        ::shutdown(client, SHUT_WR);
        run(io, client, out);
        // As HttpServer::stop: every connection closed, pending handlers finish.
        shared->stopped = true;
        shared->tick.cancel();
        for (auto& w : shared->connections)
            if (auto c = w.lock()) c->close();
        shared->connections.clear();
        io.restart();
        run(io, client, out);
    }
    ::close(client);
    check(out.empty() || out.rfind("HTTP/1.1 ", 0) == 0 || out.rfind("HTTP/1.0 ", 0) == 0);
    return 0;
}
