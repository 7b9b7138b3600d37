// fins_web_load: what finsd's web front costs the thread that also serves FINS. The
// virtual PLC and the HTTP/WebSocket server run on one io_context thread, as in finsd,
// with a tick on that thread that changes `words` words every --tick-ms. Measured: the
// CPU time that thread spends (CLOCK_THREAD_CPUTIME_ID) per second of wall time, with
// no client, with --clients clients each watching the `words` changing words, and with
// as many idle pages (each subscribed, as the page is, to the status topic and a window of
// 300 words that do not change).
// FINS shares that thread, so at saturation its request rate loses that fraction
// (docs/benchmarks.md). The WebSocket clients run on a second thread and count what
// they receive. Output: one line per case, or JSON lines with --json.
//
// --fins measures that directly, side by side: finsd's FINS/UDP server on the same
// thread, driven as fins_load's udp-32 case does (1-word MEMORY AREA READs, 32 in
// flight, from the main thread), alternately alone and with the clients watching, in
// --rounds slices each; prints both request rates (medians) and the median of the
// rounds' ratios (with / alone).
// Timing lives here, never in pass/fail tests.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/websocket.hpp>

#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"
#include "web/http_server.hpp"

#include "fins_generator.hpp"

namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
using Clock = std::chrono::steady_clock;

double thread_cpu_seconds() {
    timespec t{};
    ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

// WebSocket clients on their own thread: each subscribes (or not) and counts messages.
// --distinct: client i watches its own range D(i*512 mod 28,672) (a Watch each, not one
// shared); pingers send pings back to back instead of subscribing (a ping flood).
class Clients {
  public:
    Clients(std::uint16_t port, unsigned count, unsigned words, bool subscribe,
            bool distinct = false, bool ping = false) {
        for (unsigned i = 0; i < count; ++i) {
            auto c = std::make_unique<Client>(io_);
            auto& s = beast::get_lowest_layer(c->ws);
            s.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
            c->ws.handshake("127.0.0.1", "/ws");
            if (ping) {
                c->ping = true;
            } else if (subscribe) {
                const unsigned start = distinct ? (i * 512) % (32768 - 4096) : 0;
                c->ws.write(asio::buffer(fmt::format(
                    R"({{"op":"subscribe","id":"s","address":"D{}","count":{}}})", start, words)));
            } else {  // an idle page: the status and a grid of words nothing changes
                c->ws.write(
                    asio::buffer(std::string(R"({"op":"subscribe","id":"st","topic":"status"})")));
                c->ws.write(asio::buffer(
                    std::string(R"({"op":"subscribe","id":"g","address":"D5000","count":300})")));
            }
            clients_.push_back(std::move(c));
        }
        for (auto& c : clients_) {
            read(*c);
            if (c->ping) flood(*c);
        }
        thread_ = std::thread([this] { io_.run(); });
    }
    ~Clients() {
        asio::post(io_, [this] {
            for (auto& c : clients_)
                beast::get_lowest_layer(c->ws).close();
        });
        io_.stop();
        thread_.join();
    }
    std::uint64_t messages() const { return messages_.load(); }
    std::uint64_t bytes() const { return bytes_.load(); }

  private:
    struct Client {
        explicit Client(asio::io_context& io) : ws(io) {}
        websocket::stream<beast::tcp_stream> ws;
        beast::flat_buffer buffer;
        bool ping = false;
    };
    void flood(Client& c) {
        c.ws.async_ping({}, [this, &c](beast::error_code ec) {
            if (ec) return;  // closed (finsd's budget: 1008)
            ++messages_;
            flood(c);
        });
    }
    void read(Client& c) {
        c.ws.async_read(c.buffer, [this, &c](beast::error_code ec, std::size_t n) {
            if (ec) return;
            ++messages_;
            bytes_ += n;
            c.buffer.consume(c.buffer.size());
            read(c);
        });
    }
    asio::io_context io_{1};
    std::vector<std::unique_ptr<Client>> clients_;
    std::atomic<std::uint64_t> messages_{0};
    std::atomic<std::uint64_t> bytes_{0};
    std::thread thread_;
};

// FINS/UDP requests per second with `depth` 1-word reads of D0 in flight for `seconds`
// (fins_load's generator, its udp-32 case by default).
double fins_udp_rate(std::uint16_t port, double seconds, unsigned depth = 32) {
    const int fd = fins_bench::connect_to(false, port);
    if (fd < 0) return 0;
    const fins_bench::Frames frames{fins_bench::read_frame(0), fins_bench::read_response_size};
    const auto stats = fins_bench::drive(fd, false, frames, depth, seconds);
    ::close(fd);
    return stats.rate;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_web_load: the CPU finsd's web front takes from the FINS thread"};
    double seconds = 3.0;
    unsigned clients = 50, words = 1000, tick_ms = 10;
    bool json = false;
    app.add_option("--seconds", seconds, "Duration of each case")->capture_default_str();
    app.add_option("--clients", clients, "WebSocket clients")->capture_default_str();
    app.add_option("--words", words, "Words each client watches (all change every tick)")
        ->capture_default_str()
        ->check(CLI::Range(1u, 4096u));
    app.add_option("--tick-ms", tick_ms, "Milliseconds between changes")->capture_default_str();
    app.add_flag("--json", json, "Print JSON lines");
    bool fins_side = false, distinct = false;
    unsigned rounds = 3, pingers = 0;
    app.add_flag("--distinct", distinct,
                 "Each client watches its own range (D0-D32767 all change every tick)");
    app.add_option("--pingers", pingers,
                   "With --fins: this many clients flooding pings instead of the watchers")
        ->capture_default_str();
    app.add_flag("--fins", fins_side,
                 "FINS/UDP request rate alone and with the clients watching, and the ratio");
    app.add_option("--rounds", rounds, "With --fins: alternate the two cases this many times")
        ->capture_default_str()
        ->check(CLI::Range(1u, 51u));
    CLI11_PARSE(app, argc, argv);
    spdlog::set_level(spdlog::level::warn);

    fins::plc::Plc plc{fins::plc::cj2h()};
    asio::io_context io{1};
    fins::web::WebContext context;
    fins::server::ControlTarget target;
    target.plc = &plc;
    context.targets.push_back(target);
    context.options.max_connections = std::max(clients, pingers) * 2 + 8;
    auto web = fins::web::HttpServer::start(io, std::move(context));
    if (!web) {
        std::fprintf(stderr, "fins_web_load: cannot start the server\n");
        return 1;
    }
    // The tick: every watched word changes (a counter, as a scenario would move them).
    asio::steady_timer tick(io);
    std::uint16_t value = 0;
    std::function<void()> arm = [&] {
        tick.expires_after(std::chrono::milliseconds(tick_ms));
        tick.async_wait([&](boost::system::error_code ec) {
            if (ec) return;
            ++value;
            auto dm = plc.memory().words(fins::Region::dm);
            std::fill_n(dm.begin(), distinct ? dm.size() : std::size_t{words}, value);
            arm();
        });
    };
    arm();
    std::unique_ptr<fins::server::Server> fins_server;
    if (fins_side) {
        fins::server::ServerOptions options;
        options.port = 0;
        auto started = fins::server::Server::start(io, plc, options);
        if (!started) {
            std::fprintf(stderr, "fins_web_load: cannot start the FINS server: %s\n",
                         started.error().message().c_str());
            return 1;
        }
        fins_server = std::move(*started);
    }
    std::thread server_thread([&] { io.run(); });
    // The server thread's CPU seconds, read on that thread.
    const auto server_cpu = [&] {
        std::promise<double> p;
        auto f = p.get_future();
        asio::post(io, [&] { p.set_value(thread_cpu_seconds()); });
        return f.get();
    };
    const auto measure =
        [&](const char* name,
            const std::function<std::pair<std::uint64_t, std::uint64_t>()>& counts) {
            const double c0 = server_cpu();
            const auto w0 = Clock::now();
            const auto [m0, b0] = counts();
            std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
            const auto [m1, b1] = counts();
            const double wall = std::chrono::duration<double>(Clock::now() - w0).count();
            const double share = (server_cpu() - c0) / wall * 100.0;
            const double msgs = static_cast<double>(m1 - m0) / wall;
            const double mbytes = static_cast<double>(b1 - b0) / wall / 1e6;
            if (json)
                std::printf(
                    "{\"case\":\"%s\",\"thread_cpu_percent\":%.2f,\"ws_messages_per_s\":%.1f,"
                    "\"ws_mbytes_per_s\":%.2f}\n",
                    name, share, msgs, mbytes);
            else
                std::printf("%-26s server thread CPU %6.2f %%  WebSocket %7.1f msg/s %6.2f MB/s\n",
                            name, share, msgs, mbytes);
            std::fflush(stdout);
        };
    const auto stop = [&] {
        asio::post(io, [&] {
            tick.cancel();
            (*web)->stop();
            if (fins_server) fins_server->stop();
            io.stop();
        });
        server_thread.join();
    };
    if (fins_side) {
        std::vector<double> alone, watched, messages;
        const double slice = seconds / rounds;
        for (unsigned r = 0; r < rounds; ++r) {
            alone.push_back(fins_udp_rate(fins_server->udp_port(), slice));
            Clients watching((*web)->port(), pingers > 0 ? pingers : clients, words, true, distinct,
                             pingers > 0);
            std::this_thread::sleep_for(std::chrono::milliseconds(300));  // snapshots out
            const auto m0 = watching.messages();
            const auto w0 = Clock::now();
            watched.push_back(fins_udp_rate(fins_server->udp_port(), slice));
            messages.push_back(static_cast<double>(watching.messages() - m0) /
                               std::chrono::duration<double>(Clock::now() - w0).count());
        }
        // The ratio of each round's pair (the machine's load drifts less within a pair).
        std::vector<double> ratios;
        for (unsigned r = 0; r < rounds; ++r)
            ratios.push_back(alone[r] > 0 ? watched[r] / alone[r] : 0);
        const double a = median(alone), w = median(watched), ratio = median(ratios);
        if (json)
            std::printf(
                "{\"fins_alone_per_s\":%.0f,\"fins_with_web_per_s\":%.0f,\"ratio\":%.3f,"
                "\"ws_messages_per_s\":%.1f,\"clients\":%u,\"words\":%u}\n",
                a, w, ratio, median(messages), clients, words);
        else
            std::printf(
                "FINS/UDP alone                          %9.0f req/s\n"
                "FINS/UDP with %u clients x %u words  %9.0f req/s  (WebSocket %.1f msg/s)\n"
                "ratio (median of the rounds' ratios)    %9.3f\n",
                a, clients, words, w, median(messages), ratio);
        stop();
        return 0;
    }
    measure("no WebSocket client", [] { return std::pair<std::uint64_t, std::uint64_t>{0, 0}; });
    {
        Clients watching((*web)->port(), clients, words, true);
        std::this_thread::sleep_for(std::chrono::milliseconds(500));  // snapshots out
        measure(fmt::format("{} clients x {} words", clients, words).c_str(), [&] {
            return std::pair{watching.messages(), watching.bytes()};
        });
    }
    {
        Clients idle((*web)->port(), clients, words, false);
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        measure(fmt::format("{} idle pages", clients).c_str(), [&] {
            return std::pair{idle.messages(), idle.bytes()};
        });
    }
    stop();
    return 0;
}
