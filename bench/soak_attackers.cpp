// fins_soak's hostile clients: garbage datagrams and TCP connection churn (see
// soak_clients.hpp). Whatever finsd sends back must be well formed; everything it
// refuses it must refuse without disturbing the verifying clients.
#include <algorithm>
#include <chrono>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include <fmt/core.h>

#include "soak_clients.hpp"
#include "soak_wire.hpp"

namespace fins::soak {

namespace {

using Clock = std::chrono::steady_clock;
using Rng = std::mt19937_64;

// How long finsd may take to answer or close: far beyond any scheduling delay on a
// loaded machine, so only a stuck finsd hits it.
constexpr int closing_ms = 10'000;

std::vector<std::uint8_t> random_bytes(Rng& rng, std::size_t n) {
    std::vector<std::uint8_t> v(n);
    for (auto& b : v)
        b = static_cast<std::uint8_t>(rng());
    return v;
}

// A harmless request with random addressing and parameters.
std::vector<std::uint8_t> random_request(Rng& rng, std::uint8_t server_node, std::uint8_t source) {
    const std::uint8_t nodes[] = {0, server_node, 0xFF, static_cast<std::uint8_t>(rng())};
    const auto& code = harmless_commands[rng() % harmless_commands.size()];
    auto frame = request(nodes[rng() % 4], source, static_cast<std::uint8_t>(rng()), code,
                         random_bytes(rng, rng() % 24));
    if (rng() % 8 == 0) frame[0] |= icf_no_response;
    if (rng() % 8 == 0) frame[5] = static_cast<std::uint8_t>(rng());  // DA2: another unit
    return frame;
}

std::vector<std::uint8_t> garbage(Rng& rng, std::uint8_t server_node) {
    std::vector<std::uint8_t> g;
    switch (rng() % 7) {
        case 0:
            g = random_bytes(rng, rng() % 64);
            break;
        case 1:
            g = random_bytes(rng, rng() % 2100);
            break;
        case 2:
            g = random_request(rng, server_node, static_cast<std::uint8_t>(rng()));
            break;
        case 3:  // a request with a few bytes flipped
            g = random_request(rng, server_node, static_cast<std::uint8_t>(rng()));
            for (auto i = rng() % 4 + 1; i > 0; --i)
                g[rng() % g.size()] ^= static_cast<std::uint8_t>(rng() | 1);
            break;
        case 4:  // truncated
            g = random_request(rng, server_node, static_cast<std::uint8_t>(rng()));
            g.resize(rng() % g.size());
            break;
        case 5:  // longer than 2,012 bytes: answered 1001
            g = random_request(rng, server_node, static_cast<std::uint8_t>(rng()));
            g.resize(max_frame_size + 1 + rng() % 64, 0);
            break;
        default:  // a response frame: a server must not answer it
            g = random_request(rng, server_node, static_cast<std::uint8_t>(rng()));
            g[0] = 0xC0;
            break;
    }
    defuse(g, rng());
    return g;
}

// Every datagram finsd sends the garbage socket must be a response frame.
void drain_answers(int fd, Stats& stats) {
    std::vector<std::uint8_t> in(max_frame_size + 1);
    for (;;) {
        const ssize_t n = ::recv(fd, in.data(), in.size(), MSG_DONTWAIT);
        if (n < 0) return;
        ++stats.garbage_answers;
        const Bytes frame{in.data(), static_cast<std::size_t>(n)};
        if (static_cast<std::size_t>(n) > max_frame_size || !decode_response(frame))
            stats.mismatch(fmt::format("garbage answered with a malformed {}-byte datagram", n));
    }
}

// Reads what finsd sends until it closes (or `timeout_ms` passes); every packet must be
// a well-formed FINS/TCP packet. With `first_command`, the first one must be that
// command with a non-zero error code (a handshake refusal or an error notification).
// Returns true when finsd closed the connection.
bool read_until_close(int fd, int timeout_ms, Stats& stats, const char* what,
                      int first_command = -1) {
    set_timeouts(fd, timeout_ms);
    for (bool first = true;; first = false) {
        const auto r = receive_tcp_packet(fd);
        if (r.status == Read::eof || r.status == Read::error) {
            if (first && first_command >= 0)
                stats.mismatch(fmt::format("{}: closed without an error notification", what));
            return true;
        }
        if (r.status == Read::timeout) {
            if (first_command >= 0)
                stats.mismatch(fmt::format("{}: not closed within {} ms", what, timeout_ms));
            return false;
        }
        if (!r.well_formed()) {
            stats.mismatch(fmt::format("{}: finsd sent a malformed FINS/TCP header", what));
            return true;
        }
        if (first && first_command >= 0 &&
            (r.command() != static_cast<std::uint32_t>(first_command) || r.error() == 0))
            stats.mismatch(
                fmt::format("{}: answered command {} error {}", what, r.command(), r.error()));
    }
}

// Connects and, with `handshake`, gets a node; nullopt (and counted) when refused.
struct Connection {
    Fd fd;
    std::uint8_t node = 0;
};

std::optional<Connection> open(const Target& t, bool handshake, Stats& stats) {
    Connection c;
    c.fd = tcp_connect(t.port, closing_ms);
    if (!c.fd.valid()) {
        stats.error("churn: connect failed");
        return std::nullopt;
    }
    if (!handshake) return c;
    if (!send_all(c.fd.get(), handshake_request(0))) return std::nullopt;
    const auto r = receive_tcp_packet(c.fd.get());
    if (!r.well_formed() || r.command() != 1 || r.packet.size() != 24) {
        stats.mismatch("churn: handshake not answered");
        return std::nullopt;
    }
    if (r.error() != 0) {  // e.g. all connections in use: allowed, but worth seeing
        stats.error(fmt::format("churn: handshake refused with error {}", r.error()));
        return std::nullopt;
    }
    c.node = r.packet[19];
    return c;
}

void churn_once(const Target& t, Rng& rng, Stats& stats) {
    const auto scenario = rng() % 12;
    // 0, 1, 3, 7 and 8 are about the handshake itself: they connect without one.
    const bool handshake = scenario == 2 || (scenario >= 4 && scenario != 7 && scenario != 8);
    auto c = open(t, handshake, stats);
    if (!c) return;
    const int fd = c->fd.get();
    ++stats.connections;
    if (scenario >= 4) ++stats.malformed_streams;
    const auto frame = [&](std::uint8_t source) {
        auto f = random_request(rng, t.server_node, source);
        return tcp_packet(TcpCommand::frame, f);
    };
    switch (scenario) {
        case 0:
            break;  // connect, close
        case 1:
            c->fd.abort();
            ++stats.resets;
            return;  // connect, reset
        case 2: {    // a read, answered
            auto f = request(t.server_node, c->node, 7, {0x01, 0x01}, {0x82, 0, 0, 0, 0, 1});
            send_all(fd, tcp_packet(TcpCommand::frame, f));
            const auto r = receive_tcp_packet(fd);
            if (!r.well_formed() || r.command() != 2 || r.packet.size() != tcp_header_size + 16)
                stats.mismatch("churn: read on a fresh connection not answered");
            break;
        }
        case 3: {  // half a handshake
            auto h = handshake_request(0);
            h.resize(rng() % h.size());
            send_all(fd, h);
            break;
        }
        case 4: {  // bad magic
            auto p = frame(c->node);
            p[rng() % 4] ^= 0x20;
            send_all(fd, p);
            read_until_close(fd, closing_ms, stats, "bad magic", 3);
            break;
        }
        case 5:  // length beyond the largest frame
            send_all(fd, tcp_packet(TcpCommand::frame, {}, max_frame_size + 1 + rng() % 100));
            read_until_close(fd, closing_ms, stats, "oversized length", 3);
            break;
        case 6:  // a second handshake
            send_all(fd, handshake_request(0));
            read_until_close(fd, closing_ms, stats, "second handshake", 3);
            break;
        case 7:  // the server's own node: refused in the handshake
            send_all(fd, handshake_request(t.server_node));
            read_until_close(fd, closing_ms, stats, "handshake as the server's node", 1);
            break;
        case 8:  // a frame before any handshake
            send_all(fd, frame(0xEF));
            read_until_close(fd, closing_ms, stats, "frame before handshake", 3);
            break;
        case 9:  // harmless frames, some from a node that is not ours
            for (auto i = rng() % 4 + 1; i > 0; --i)
                send_all(fd, frame(rng() % 4 == 0 ? static_cast<std::uint8_t>(rng()) : c->node));
            read_until_close(fd, 50, stats, "frames");
            break;
        case 10:  // random bytes after the handshake
            send_all(fd, random_bytes(rng, rng() % 200 + 1));
            read_until_close(fd, 50, stats, "random stream");
            break;
        default: {  // a frame cut short, then gone
            auto p = frame(c->node);
            p.resize(rng() % p.size());
            send_all(fd, p);
            break;
        }
    }
    if (rng() % 2 == 0) {
        c->fd.abort();
        ++stats.resets;
    }
}

void pace(Clock::time_point& next, unsigned per_second) {
    next += std::chrono::microseconds(1'000'000 / std::max(per_second, 1u));
    std::this_thread::sleep_until(next);
}

}  // namespace

void run_garbage_sender(Target t, unsigned per_second, std::uint64_t seed, Stats& stats,
                        const std::atomic<bool>& stop) {
    Rng rng(seed);
    Fd fd = udp_socket(t.port, 100);
    if (!fd.valid()) return stats.mismatch("garbage: no socket");
    auto next = Clock::now();
    while (!stop) {
        const auto g = garbage(rng, t.server_node);
        // Errors (e.g. a refused port after an earlier datagram) change nothing here.
        (void)::send(fd.get(), g.data(), g.size(), 0);
        ++stats.garbage_datagrams;
        drain_answers(fd.get(), stats);
        pace(next, per_second);
    }
}

void run_churner(Target t, unsigned per_second, std::uint64_t seed, Stats& stats,
                 const std::atomic<bool>& stop) {
    Rng rng(seed);
    auto next = Clock::now();
    while (!stop) {
        churn_once(t, rng, stats);
        pace(next, per_second);
    }
}

}  // namespace fins::soak
