// libFuzzer target: finsd's Host Link slave (server::SerialSession) in process. A
// pseudo-terminal pair stands in for the serial line: the session opens the slave side by
// its path, exactly as `finsd --serial cpu=DEVICE` does, and the input goes into the
// master side in chunks, with the io_context run between them (so the session sees
// frames cut anywhere, glued, garbage, over-long lines and bad FCS).
//
// Input: records of [length, bytes]; a record cut short by the end of the input keeps
// what is there.
//
// Checked beyond "no crash": everything the session writes on the line is a sequence of
// well-formed Host Link answers for unit 00 ("@00FA" ... FCS "*" CR, decodable as a
// response); and after any input the session still serves: a CR (ending whatever partial
// line the input left) and a sentinel read of D0 are answered within a bounded time.
#include <fcntl.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>

#include "fins/frame.hpp"
#include "fins/host_link.hpp"
#include "plc/plc.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/serial/serial_session.hpp"
#include "transport/asio.hpp"

namespace {

using namespace fins;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

constexpr std::uint8_t sentinel_sid = 0x7E;

// The sentinel: a direct-form 01 01 read of one word at D0, wait time 0.
std::vector<std::uint8_t> sentinel_frame() {
    std::vector<std::uint8_t> frame(max_frame_size);
    Header h;
    h.service_id = sentinel_sid;
    const std::array<std::uint8_t, 6> params{0x82, 0x00, 0x00, 0x00, 0x00, 0x01};
    const auto n = encode_request(h, CommandCode{0x01, 0x01}, params, frame);
    check(n.has_value());
    std::array<std::uint8_t, 2 * host_link_max_command_chars> out{};
    const auto chars =
        encode_host_link_command(0, 0, HostLinkForm::direct, Bytes{frame.data(), *n}, out);
    check(chars.has_value());
    return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(*chars)};
}

struct Line {
    asio::io_context io{1};
    plc::Plc plc;
    server::Dispatcher dispatcher{plc, {0, 1, 0}};
    std::shared_ptr<server::SerialSession> session;
    int master = -1;
    int slave = -1;  // kept open: the line never hangs up under the session
    std::vector<std::uint8_t> sentinel = sentinel_frame();

    Line() {
        spdlog::set_level(spdlog::level::off);
        std::array<char, 128> name{};
        check(::openpty(&master, &slave, name.data(), nullptr, nullptr) == 0);
        termios raw{};
        check(::tcgetattr(slave, &raw) == 0);
        ::cfmakeraw(&raw);
        check(::tcsetattr(slave, TCSANOW, &raw) == 0);
        check(::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK) == 0);
        server::SerialSessionOptions options;
        options.line.device = name.data();
        session = std::make_shared<server::SerialSession>(io, dispatcher, options);
        check(session->start());
    }

    void write(const std::uint8_t* p, std::size_t n) {
        // A pty takes a few KB at a time: run the session while the rest waits.
        for (int spins = 0; n > 0 && spins < 1000; ++spins) {
            const ssize_t w = ::write(master, p, n);
            if (w > 0) {
                p += w;
                n -= static_cast<std::size_t>(w);
            }
            io.poll();
        }
        check(n == 0);
    }

    // Reads what the session wrote and checks each whole answer; true once the
    // sentinel's answer came. `stream` keeps a partial answer for the next call.
    bool drain(std::vector<std::uint8_t>& stream) {
        std::array<std::uint8_t, 4096> buf{};
        for (;;) {
            const ssize_t n = ::read(master, buf.data(), buf.size());
            if (n <= 0) break;
            stream.insert(stream.end(), buf.begin(), buf.begin() + n);
        }
        bool seen = false;
        std::size_t at = 0;
        for (;;) {
            const auto scan = scan_host_link(Bytes{stream.data() + at, stream.size() - at});
            if (scan.status == HostLinkScan::Status::need_more) break;
            // The session writes answers only: no garbage, no over-long line.
            check(scan.status == HostLinkScan::Status::frame);
            std::array<std::uint8_t, host_link_max_fins_response> fins{};
            const auto f = decode_host_link(scan.frame, true, fins);
            check(f.has_value() && f->unit == 0);
            if (f->fins_size > 0) {
                const auto rsp = decode_response(Bytes{fins.data(), f->fins_size});
                check(rsp.has_value());
                if (rsp->header.service_id == sentinel_sid &&
                    rsp->command == CommandCode{0x01, 0x01})
                    seen = true;
            }
            at += scan.consumed;
        }
        stream.erase(stream.begin(), stream.begin() + static_cast<std::ptrdiff_t>(at));
        return seen;
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static Line line;
    std::vector<std::uint8_t> stream;
    std::size_t at = 0;
    while (at < size) {
        const std::size_t length = std::min<std::size_t>(data[at], size - at - 1);
        line.write(data + at + 1, length);
        line.io.poll();
        line.drain(stream);
        at += 1 + length;
    }
    const std::uint8_t cr = '\r';
    line.write(&cr, 1);
    line.write(line.sentinel.data(), line.sentinel.size());
    // Answers the input asked to delay (wait digit up to F = 150 ms each) come first.
    bool answered = false;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    for (int step = 0; step < 100000 && !answered && std::chrono::steady_clock::now() < give_up;
         ++step) {
        line.io.run_one_for(std::chrono::milliseconds(2));
        answered = line.drain(stream);
    }
    check(answered);
    check(line.session->is_open());
    return 0;
}
