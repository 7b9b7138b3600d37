#include "soak_clients.hpp"

#include <cstdio>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include <fmt/core.h>

#include "soak_wire.hpp"

namespace fins::soak {

void Stats::print(const char* kind, const std::string& what, std::uint64_t count) {
    // The first ones tell what went wrong; thousands of copies would bury the report.
    if (count > 20) return;
    const std::lock_guard lock(print_mutex_);
    std::fprintf(stderr, "soak: %s: %s%s\n", kind, what.c_str(),
                 count == 20 ? " (further ones are counted, not printed)" : "");
}

void Stats::mismatch(const std::string& what) {
    print("MISMATCH", what, ++mismatches);
}

void Stats::error(const std::string& what) {
    print("error", what, ++errors);
}

namespace {

constexpr std::uint8_t dm = 0x82;
constexpr int udp_timeout_ms = 1000;
constexpr int tcp_timeout_ms = 10'000;  // only a stuck finsd takes this long

std::vector<std::uint8_t> dm_address(std::uint16_t word) {
    return {dm, static_cast<std::uint8_t>(word >> 8), static_cast<std::uint8_t>(word), 0};
}

void put16(std::vector<std::uint8_t>& v, std::uint16_t x) {
    v.push_back(static_cast<std::uint8_t>(x >> 8));
    v.push_back(static_cast<std::uint8_t>(x));
}

// One client's words as it believes finsd holds them. A write whose answer never came
// may or may not have happened: its words become unknown, and the next read of them
// (answered after it, on the same socket, so in order) says which.
class Verifier {
  public:
    Verifier(Range r, std::uint64_t seed, Stats& stats, std::string name)
        : range_(r),
          value_(r.count),
          known_(r.count),
          rng_(seed),
          stats_(stats),
          name_(std::move(name)) {}

    struct Op {
        CommandCode code;
        std::vector<std::uint8_t> params;
        std::vector<std::uint16_t> offsets;  // words written or read, in answer order
        std::vector<std::uint16_t> values;   // written values
    };

    Op next() {
        Op op;
        const auto kind = pick(10);
        if (kind < 2) {  // 01 04: up to 8 single words anywhere in the range
            op.code = {0x01, 0x04};
            for (auto i = pick(8) + 1; i > 0; --i) {
                const auto o = static_cast<std::uint16_t>(pick(range_.count));
                op.offsets.push_back(o);
                const auto a = dm_address(static_cast<std::uint16_t>(range_.first + o));
                op.params.insert(op.params.end(), a.begin(), a.end());
            }
            return op;
        }
        const auto o = static_cast<std::uint16_t>(pick(range_.count));
        const auto n = static_cast<std::uint16_t>(pick(range_.count - o) + 1u);
        op.params = dm_address(static_cast<std::uint16_t>(range_.first + o));
        put16(op.params, n);
        for (std::uint16_t i = 0; i < n; ++i)
            op.offsets.push_back(static_cast<std::uint16_t>(o + i));
        if (kind < 6) {
            op.code = {0x01, 0x01};
        } else if (kind < 9) {
            op.code = {0x01, 0x02};
            for (std::uint16_t i = 0; i < n; ++i) {
                op.values.push_back(static_cast<std::uint16_t>(rng_()));
                put16(op.params, op.values.back());
            }
        } else {
            op.code = {0x01, 0x03};
            op.values.assign(n, static_cast<std::uint16_t>(rng_()));
            put16(op.params, op.values.front());
        }
        return op;
    }

    // The answer's data (after the end code) or nothing when the answer never came.
    // Returns false on a mismatch.
    bool done(const Op& op, std::optional<Bytes> data) {
        const bool write = !op.values.empty();
        if (!data) {
            if (write)
                for (auto o : op.offsets)
                    known_[o] = false;
            return true;
        }
        if (write) {
            if (!data->empty())
                return fail(op, fmt::format("{} data bytes after a write", data->size()));
            for (std::size_t i = 0; i < op.offsets.size(); ++i) {
                value_[op.offsets[i]] = op.values[i];
                known_[op.offsets[i]] = true;
            }
            return true;
        }
        const bool multi = op.code == CommandCode{0x01, 0x04};
        const std::size_t item = multi ? 3 : 2;
        if (data->size() != op.offsets.size() * item)
            return fail(op,
                        fmt::format("{} data bytes for {} words", data->size(), op.offsets.size()));
        for (std::size_t i = 0; i < op.offsets.size(); ++i) {
            const auto* p = data->data() + i * item;
            if (multi && p[0] != dm)
                return fail(op, fmt::format("item {} area code {:02X}", i, p[0]));
            if (multi) ++p;
            const auto got = static_cast<std::uint16_t>((p[0] << 8) | p[1]);
            const auto o = op.offsets[i];
            if (known_[o] && value_[o] != got)
                return fail(op, fmt::format("D{} is {:04X}, wrote {:04X}", range_.first + o, got,
                                            value_[o]));
            value_[o] = got;
            known_[o] = true;
        }
        return true;
    }

    bool fail(const Op& op, const std::string& what) {
        stats_.mismatch(fmt::format("{} {:02X}{:02X}: {}", name_, op.code.main, op.code.sub, what));
        return false;
    }

    unsigned pick(unsigned n) { return static_cast<unsigned>(rng_() % n); }

  private:
    Range range_;
    std::vector<std::uint16_t> value_;
    std::vector<bool> known_;
    std::mt19937_64 rng_;
    Stats& stats_;
    std::string name_;
};

// The checks every answer to a verifying client's request passes before its data is
// looked at: a response frame, for our node, with our SID and command, end code 0000.
std::optional<Bytes> check_answer(Verifier& v, const Verifier::Op& op, Bytes frame,
                                  std::uint8_t node) {
    auto rsp = decode_response(frame);
    if (!rsp) {
        v.fail(op, fmt::format("undecodable answer of {} bytes", frame.size()));
        return std::nullopt;
    }
    if (rsp->header.destination.node != node || !(rsp->command == op.code) ||
        rsp->code.raw() != 0) {
        v.fail(op, fmt::format("answer to node {} for {:02X}{:02X}, end code {:04X}",
                               rsp->header.destination.node, rsp->command.main, rsp->command.sub,
                               rsp->code.raw()));
        return std::nullopt;
    }
    return rsp->data;
}

}  // namespace

void run_udp_client(Target t, Range r, std::uint8_t node, std::uint64_t seed, Stats& stats,
                    const std::atomic<bool>& stop) {
    const auto name = fmt::format("udp node {}", node);
    Verifier v(r, seed, stats, name);
    Fd fd = udp_socket(t.port, udp_timeout_ms);
    if (!fd.valid()) return stats.mismatch(name + ": no socket");
    std::uint8_t sid = 0;
    std::vector<std::uint8_t> in(max_frame_size + 1);
    while (!stop) {
        const auto op = v.next();
        const auto frame = request(0, node, ++sid, op.code, op.params);
        if (::send(fd.get(), frame.data(), frame.size(), 0) != static_cast<ssize_t>(frame.size())) {
            stats.error(name + ": send failed");
            v.done(op, std::nullopt);
            continue;
        }
        std::optional<Bytes> data;
        bool answered = false;
        while (!answered) {
            const ssize_t n = ::recv(fd.get(), in.data(), in.size(), 0);
            if (n < 0) break;  // timeout: lost on the way there or back
            const Bytes got{in.data(), static_cast<std::size_t>(n)};
            // An answer to an earlier, timed-out request: its outcome is already unknown.
            if (n >= 10 && in[9] != sid) continue;
            answered = true;
            data = check_answer(v, op, got, node);
            if (!data) return;
        }
        if (!answered) stats.error(name + ": no answer within 1 s");
        if (!v.done(op, data)) return;
        if (answered) ++stats.udp_verified;
    }
}

void run_tcp_client(Target t, Range r, std::uint64_t seed, Stats& stats, std::atomic<int>& ready,
                    const std::atomic<bool>& stop) {
    std::string name = fmt::format("tcp D{}", r.first);
    Verifier v(r, seed, stats, name);
    Fd fd = tcp_connect(t.port, tcp_timeout_ms);
    if (!fd.valid() || !send_all(fd.get(), handshake_request(0)))
        return stats.mismatch(name + ": cannot connect");
    const auto hs = receive_tcp_packet(fd.get());
    if (!hs.well_formed() || hs.command() != 1 || hs.error() != 0 || hs.packet.size() != 24)
        return stats.mismatch(name + ": handshake refused");
    const auto node = hs.packet[19];
    name += fmt::format(" node {}", node);
    ++ready;
    std::uint8_t sid = 0;
    while (!stop) {
        const auto op = v.next();
        const auto frame = request(t.server_node, node, ++sid, op.code, op.params);
        if (!send_all(fd.get(), tcp_packet(TcpCommand::frame, frame)))
            return stats.mismatch(name + ": connection lost on send");
        const auto in = receive_tcp_packet(fd.get());
        if (in.status == Read::timeout) return stats.mismatch(name + ": no answer within 10 s");
        if (!in.well_formed() || in.command() != 2)
            return stats.mismatch(name + ": connection lost or not a FRAME SEND");
        const Bytes got{in.packet.data() + tcp_header_size, in.packet.size() - tcp_header_size};
        if (got.size() >= 10 && got[9] != sid) return (void)v.fail(op, "answer with another SID");
        const auto data = check_answer(v, op, got, node);
        if (!data || !v.done(op, data)) return;
        ++stats.tcp_verified;
    }
}

}  // namespace fins::soak
