// fins_host_link_load: the Host Link request rate of fins::Client against finsd's serial
// session (the real SerialSession + Dispatcher, in this process on a thread of its own)
// over socat pty pairs, compared with the line's own limit.
//
// A pty has no baud rate: bytes cross it as fast as the kernel copies them. So two runs:
//   pty     client <-> pty pair <-> server: what finskit itself costs per request.
//   paced   client <-> pty pair <-> line emulator <-> pty pair <-> server: the emulator
//           holds every chunk until its last character would have arrived on a real line
//           at BAUD with BITS per character (7E2: 11 bits), in each direction.
// Line limit per request = (command characters + response characters) x BITS / BAUD;
// rate limit = 1 / that. The paced run's rate / limit is the figure (aim: >= 0.8).
//   fins_host_link_load [--baud 115200] [--bits 11] [--seconds 3] [--words 1]
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include <fmt/core.h>
#include <CLI/CLI.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/client.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/host_link.hpp"
#include "integration/support/pty_pair.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/serial/serial_session.hpp"
#include "transport/asio.hpp"

namespace {

using Clock = std::chrono::steady_clock;

int open_raw(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY);
    termios t{};
    if (fd >= 0 && ::tcgetattr(fd, &t) == 0) {
        ::cfmakeraw(&t);
        ::tcsetattr(fd, TCSANOW, &t);
    }
    return fd;
}

// Forwards bytes between two fds, each direction delayed to the line's character time.
class LineEmulator {
  public:
    LineEmulator(const std::string& a, const std::string& b, double char_seconds)
        : fds_{open_raw(a), open_raw(b)}, char_time_(std::chrono::duration<double>(char_seconds)) {
        thread_ = std::thread([this] { run(); });
    }
    ~LineEmulator() {
        stop_ = true;
        thread_.join();
        ::close(fds_[0]);
        ::close(fds_[1]);
    }

  private:
    void run() {
        Clock::time_point free_at[2] = {Clock::now(), Clock::now()};
        char buf[4096];
        while (!stop_) {
            pollfd p[2] = {{fds_[0], POLLIN, 0}, {fds_[1], POLLIN, 0}};
            if (::poll(p, 2, 50) <= 0) continue;
            for (int from = 0; from < 2; ++from) {
                if ((p[from].revents & POLLIN) == 0) continue;
                const auto n = ::read(fds_[from], buf, sizeof buf);
                if (n <= 0) return;
                // The last of these characters arrives n character times after the line
                // was free (or after now, if it was idle).
                auto& free = free_at[from];
                free = std::max(free, Clock::now()) +
                       std::chrono::duration_cast<Clock::duration>(char_time_ * n);
                std::this_thread::sleep_until(free);
                // Time the emulator held the bytes beyond the line's own time: its wake-up
                // latency on a busy machine, which a UART does not have.
                late_ns_ +=
                    std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - free)
                        .count();
                const int to = 1 - from;
                for (ssize_t done = 0; done < n;) {
                    const auto w =
                        ::write(fds_[to], buf + done, static_cast<std::size_t>(n - done));
                    if (w <= 0) return;
                    done += w;
                }
            }
        }
    }

  public:
    [[nodiscard]] double late_seconds() const { return static_cast<double>(late_ns_) * 1e-9; }

  private:
    std::atomic<std::int64_t> late_ns_{0};
    int fds_[2];
    std::chrono::duration<double> char_time_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

struct Result {
    long requests = 0;
    double seconds = 0;
};

// Sequential reads (Host Link is half duplex: one on the line at a time) for `seconds`.
// `started` runs after the warm-up, when the measured time begins.
Result measure(const std::string& device, unsigned baud, unsigned words, double seconds,
               const std::function<void()>& started = {}) {
    fins::ClientOptions o;
    o.protocol = fins::ClientOptions::Protocol::serial;
    o.serial.device = device;
    o.serial.baud = baud;
    o.timeout = std::chrono::milliseconds(2000);
    auto client = fins::Client::connect(o);
    if (!client) {
        std::fprintf(stderr, "connect: %s\n", client.error().message().c_str());
        return {};
    }
    const auto d0 = fins::to_memory_address(fins::parse_address("D0").value()).value();
    const fins::MemoryAreaRead read{d0, static_cast<std::uint16_t>(words)};
    for (int i = 0; i < 20; ++i)  // warm-up
        (void)(*client)->send(read);
    Result r;
    if (started) started();
    const auto start = Clock::now();
    const auto end = start + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) {
        if (!(*client)->send(read)) {
            std::fprintf(stderr, "request failed\n");
            break;
        }
        ++r.requests;
    }
    r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Host Link request rate over socat ptys against the line's limit"};
    unsigned baud = 115200;
    unsigned bits = 11;
    double seconds = 3;
    unsigned words = 1;
    app.add_option("--baud", baud, "Line rate to emulate")->capture_default_str();
    app.add_option("--bits", bits, "Bits per character (7E2: 11)")->capture_default_str();
    app.add_option("--seconds", seconds, "Seconds per run")->capture_default_str();
    app.add_option("--words", words, "Words per MEMORY AREA READ (1-269)")
        ->capture_default_str()
        ->check(CLI::Range(1, 269));
    CLI11_PARSE(app, argc, argv);

    // Characters per request: direct form, read `words` words.
    // Command: "@" UU "FA" W ICF DA2 SA2 SID (8) MRC SRC (4) area+address+count (12) FCS "*" CR.
    const double command_chars = 1 + 2 + 2 + 1 + 8 + 4 + 12 + 4;
    // Response: "@" UU "FA" EC ICF DA2 SA2 SID MRC SRC MRES SRES data FCS "*" CR.
    const double response_chars = 1 + 2 + 2 + 2 + 8 + 4 + 4 + 4.0 * words + 4;
    const double line_seconds = (command_chars + response_chars) * bits / baud;
    const double limit = 1.0 / line_seconds;

    fins::plc::Plc plc{fins::plc::cj2h()};
    fins::server::Dispatcher dispatcher(plc, fins::NodeAddress{0, 1, 0});
    asio::io_context io{1};
    fins::test::PtyPair client_pair;
    fins::test::PtyPair server_pair;
    if (!client_pair.ok() || !server_pair.ok()) {
        std::fprintf(stderr, "socat did not start\n");
        return 3;
    }
    fins::server::SerialSessionOptions so;
    so.line.device = server_pair.b();
    so.line.baud = baud;
    auto session = std::make_shared<fins::server::SerialSession>(io, dispatcher, so);
    if (!session->start()) return 3;
    auto guard = asio::make_work_guard(io);
    std::thread server([&] { io.run(); });

    fmt::print(
        "Host Link, read {} word(s), {} + {} characters per request, {} bit/s, {} bits per "
        "character\n",
        words, command_chars, response_chars, baud, bits);
    fmt::print("line limit: {:.1f} requests/s ({:.0f} us per request)\n", limit,
               line_seconds * 1e6);

    // 1. Straight over one pty pair (server on its far end).
    const auto raw = measure(server_pair.a(), baud, words, seconds);
    const double raw_rate = static_cast<double>(raw.requests) / raw.seconds;
    fmt::print(
        "pty (no line): {:.1f} requests/s ({:.0f} us per request) = {:.2f} x the line limit\n",
        raw_rate, 1e6 / raw_rate, raw_rate / limit);

    // 2. Through the line emulator: client_pair.a <-> [b ... server_pair.a] <-> server.
    {
        LineEmulator line(client_pair.b(), server_pair.a(), static_cast<double>(bits) / baud);
        double late_before = 0;
        const auto paced = measure(client_pair.a(), baud, words, seconds,
                                   [&] { late_before = line.late_seconds(); });
        const double late = line.late_seconds() - late_before;
        const double rate = static_cast<double>(paced.requests) / paced.seconds;
        fmt::print(
            "paced at {} bit/s: {:.1f} requests/s ({:.0f} us per request) = {:.2f} of the "
            "line limit\n",
            baud, rate, 1e6 / rate, rate / limit);
        // Without the emulator's own lateness, which the measured time includes.
        const double corrected =
            static_cast<double>(paced.requests) / std::max(paced.seconds - late, 1e-9);
        fmt::print(
            "  emulator lateness {:.0f} us per request; without it {:.1f} requests/s = "
            "{:.2f} of the line limit\n",
            paced.requests > 0 ? late / static_cast<double>(paced.requests) * 1e6 : 0.0, corrected,
            corrected / limit);
    }
    guard.reset();
    asio::post(io, [&] { session->close(); });
    server.join();
    return 0;
}
