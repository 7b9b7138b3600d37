// libFuzzer target: a whole finsd session in process. A fins::server::Server (public
// API only) serves a virtual PLC on 127.0.0.1, port 0, on this thread's io_context; the
// input is cut into UDP datagrams and chunks of one FINS/TCP byte stream, which go to
// it over loopback.
//
// Input: one flag byte (bit 0: no automatic handshake, the stream starts with the
// input's own bytes), then records of [kind, length high, length low, bytes]; an even
// kind is a datagram, an odd one the next chunk of the TCP stream (the io_context runs
// between chunks, so the server sees them as separate reads). A record cut short by the
// end of the input keeps what is there.
//
// The server has every route a frame can take: it is unit 0 (1.1) of CPU Unit A in a
// plant whose routing tables put network 2 on unit 1 (2.1) and network 3 behind 2.5
// (CPU Unit B, no tables of its own); and it serves a Serial Gateway port (unit 80) and
// a port whose Host Link slaves are network 5 (unit 81), on a device that does not
// exist (a request there is answered 0205, through the session's reply path).
//
// Checked beyond "no crash": every datagram finsd sends is a response frame of at most
// 2,012 bytes; everything it sends on TCP is a sequence of well-formed FINS/TCP packets
// whose frames are response frames; the session ends (a sentinel datagram is answered
// and the stream, closed for writing after the input, is closed by finsd) within a
// bounded number of io_context steps; and its connection slot is free afterwards.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>

#include "every_route.hpp"
#include "fins/frame.hpp"
#include "fins/tcp.hpp"
#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/routing/router.hpp"
#include "server/serial/serial_ports.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace {

using namespace fins;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

// Client sockets: plain non-blocking descriptors, so the server's io_context is the only
// thing that runs handlers.
int client_socket(int type, std::uint16_t port) {
    const int fd = ::socket(AF_INET, type | SOCK_NONBLOCK, 0);
    check(fd >= 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons(port);
    // On loopback a TCP connect completes in the kernel's backlog, before any accept.
    const int rc = ::connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof to);
    check(rc == 0 || errno == EINPROGRESS);
    return fd;
}

struct Session {
    asio::io_context io{1};
    plc::Plc plc;
    plc::Plc remote;  // CPU Unit B
    server::Router router;
    server::Dispatcher a2{plc, {2, 1, 0}};
    server::Dispatcher b2{remote, {2, 5, 0}};
    server::SerialPorts ports;
    std::unique_ptr<server::Server> server;
    int udp = -1;
    std::uint8_t sentinel_sid = 0;

    Session() {
        spdlog::set_level(spdlog::level::off);
        const auto cpu_a = router.add_cpu(plc, false);
        const auto cpu_b = router.add_cpu(remote, false);
        const auto a1_port = router.add_port(cpu_a, 0, {1, 1, 0});
        for (const auto& [port, dispatcher] :
             {std::pair{router.add_port(cpu_a, 1, {2, 1, 0}), &a2},
              std::pair{router.add_port(cpu_b, 0, {2, 5, 0}), &b2}}) {
            dispatcher->attach(router, port);
            router.set_dispatcher(port, *dispatcher);
        }
        fins_fuzz::write_routing_tables(plc);

        server::ServerOptions options;
        options.bind_address = "127.0.0.1";
        options.port = 0;
        options.network = 1;
        options.node = 1;
        options.router = &router;
        options.router_port = a1_port;
        auto started = server::Server::start(io, plc, options);
        check(started.has_value());
        server = std::move(*started);
        router.set_dispatcher(a1_port, server->dispatcher());

        fins_fuzz::add_gateway_ports(io, ports);
        server->attach_serial_ports(&ports);
        udp = client_socket(SOCK_DGRAM, server->udp_port());
    }
};

// Reads the datagrams waiting on the UDP socket; true once the sentinel's answer came.
bool drain_udp(int fd, std::uint8_t sentinel_sid) {
    std::vector<std::uint8_t> in(max_frame_size + 1);
    bool sentinel = false;
    for (;;) {
        const ssize_t n = ::recv(fd, in.data(), in.size(), MSG_DONTWAIT);
        if (n < 0) return sentinel;
        check(static_cast<std::size_t>(n) <= max_frame_size);
        auto rsp = decode_response(Bytes{in.data(), static_cast<std::size_t>(n)});
        check(rsp.has_value());
        if (rsp->header.service_id == sentinel_sid && rsp->header.destination.node == 0x7E &&
            rsp->command == CommandCode{0x01, 0x01})
            sentinel = true;
    }
}

// Appends what the TCP socket has to `stream`, checks the whole packets in it and drops
// them; true at EOF or on a reset.
bool drain_tcp(int fd, std::vector<std::uint8_t>& stream) {
    std::uint8_t buf[4096];
    bool closed = false;
    for (;;) {
        const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
        if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK)) {
            closed = true;
            break;
        }
        if (n < 0) break;
        stream.insert(stream.end(), buf, buf + n);
    }
    for (;;) {
        const auto p = parse_tcp_frame(Bytes{stream.data(), stream.size()});
        check(p.status != TcpParse::Status::error);
        if (p.status == TcpParse::Status::need_more) break;
        if (p.packet.command == static_cast<std::uint32_t>(TcpCommand::frame))
            check(decode_response(p.packet.data).has_value());
        stream.erase(stream.begin(), stream.begin() + static_cast<std::ptrdiff_t>(p.consumed));
    }
    if (closed) check(stream.empty());  // no half packet before the close
    return closed;
}

void send_chunk(Session& s, int fd, const std::uint8_t* data, std::size_t size) {
    // The server may have closed already (an envelope error): the rest goes nowhere.
    for (int attempt = 0; size > 0 && attempt < 100; ++attempt) {
        const ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return;
        if (n > 0) {
            data += n;
            size -= static_cast<std::size_t>(n);
        }
        s.io.poll();
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static Session s;
    if (size == 0) return 0;
    drain_udp(s.udp, 0);  // late answers from the previous input
    const bool handshake = (data[0] & 1) == 0;
    const int tcp = client_socket(SOCK_STREAM, s.server->tcp_port());
    if (handshake) {
        std::uint8_t request[20];
        ByteWriter w{MutableBytes{request, sizeof request}};
        write_node_address_request(w, 0);
        send_chunk(s, tcp, request, sizeof request);
    }
    std::size_t at = 1;
    for (int records = 0; at < size && records < 256; ++records) {
        const std::uint8_t kind = data[at++];
        std::size_t length = 0;
        for (int i = 0; i < 2 && at < size; ++i)
            length = (length << 8) | data[at++];
        length = std::min(length, size - at);
        if ((kind & 1) == 0)
            (void)::send(s.udp, data + at, length, MSG_DONTWAIT);
        else
            send_chunk(s, tcp, data + at, length);
        at += length;
        s.io.poll();
    }
    ::shutdown(tcp, SHUT_WR);

    // The sentinel: answered only after every datagram before it was handled.
    std::uint8_t sentinel[18];
    Header h;
    h.source = {0, 0x7E, 0};
    h.service_id = ++s.sentinel_sid;
    const std::uint8_t read_d0[] = {0x82, 0, 0, 0, 0, 1};
    const auto n = encode_request(h, {0x01, 0x01}, Bytes{read_d0, sizeof read_d0},
                                  MutableBytes{sentinel, sizeof sentinel});
    check(n.has_value());
    check(::send(s.udp, sentinel, *n, 0) == static_cast<ssize_t>(*n));

    std::vector<std::uint8_t> stream;
    bool udp_done = false;
    bool tcp_done = false;
    for (int step = 0; step < 1000 && !(udp_done && tcp_done); ++step) {
        s.io.run_one_for(std::chrono::milliseconds(5));
        s.io.poll();
        udp_done = udp_done || drain_udp(s.udp, s.sentinel_sid);
        tcp_done = tcp_done || drain_tcp(tcp, stream);
    }
    check(udp_done && tcp_done);  // else finsd hung on this input

    // A reset instead of a FIN: no TIME_WAIT per input.
    linger l{1, 0};
    ::setsockopt(tcp, SOL_SOCKET, SO_LINGER, &l, sizeof l);
    ::close(tcp);
    for (int step = 0; step < 1000 && s.server->tcp_connections() != 0; ++step)
        s.io.run_one_for(std::chrono::milliseconds(1));
    check(s.server->tcp_connections() == 0);
    return 0;
}
