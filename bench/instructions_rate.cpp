// Send/Rcv/SendCmd rate between two finsd nodes (W596 3 network instructions).
//
//   build/bin/fins_instructions_rate [--kind send|recv|sendcmd] [--in-flight 1..32]
//                                    [--words 10] [--seconds 3] [--transport udp|tcp]
//
// Node 1 and node 5 are two Servers on 127.0.0.1, each on its own io_context thread
// (as two finsd processes are): node 1 keeps `in-flight` instructions running against
// node 5 and counts completions. Prints instructions per second. SendCmd sends a
// 01 01 read of `words` words (D2000). --transport tcp: node 5 serves FINS/TCP only and
// node 1 reaches it over a FINS/TCP client connection ([[remote]] transport = "tcp").
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "plc/plc.hpp"
#include "server/instructions/network_instructions.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace {

using namespace fins;
using Clock = std::chrono::steady_clock;

struct Runner {
    server::NetworkInstructions& engine;
    server::InstructionRequest request;
    Clock::time_point end;
    std::uint64_t done = 0;
    std::uint64_t errors = 0;
    unsigned running = 0;
    std::function<void()> finished;            // the last instruction ended after `end`
    std::map<std::string, std::uint64_t> why;  // errors by error ID, end code and detail

    void launch() {
        ++running;
        engine.start(request, [this](const server::InstructionResult& r) {
            --running;
            ++(r.done() ? done : errors);
            if (!r.done())
                ++why[fmt::format("{:04X} {:04X} {}", r.error_id, r.error_id_ex, r.detail)];
            if (Clock::now() < end)
                launch();
            else if (running == 0)
                finished();
        });
    }
};

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Send/Rcv rate between two finsd nodes"};
    std::string kind = "send";
    unsigned in_flight = 1;
    unsigned words = 10;
    double seconds = 3;
    std::string transport = "udp";
    app.add_option("--kind", kind, "send, recv or sendcmd")
        ->check(CLI::IsMember({"send", "recv", "sendcmd"}));
    app.add_option("--transport", transport, "udp, or tcp: a FINS/TCP client connection")
        ->check(CLI::IsMember({"udp", "tcp"}));
    app.add_option("--in-flight", in_flight, "Instructions at once (1-32)")
        ->check(CLI::Range(1, 32));
    app.add_option("--words", words, "Words per instruction")->check(CLI::Range(1, 990));
    app.add_option("--seconds", seconds, "Duration")->check(CLI::Range(0.5, 60.0));
    CLI11_PARSE(app, argc, argv);

    asio::io_context io5{1};
    plc::Plc plc5;
    server::ServerOptions o5;
    o5.port = 0;
    o5.node = 5;
    const bool tcp = transport == "tcp";
    o5.tcp = tcp;
    o5.udp = !tcp;
    auto node5 = server::Server::start(io5, plc5, o5);
    if (!node5) {
        std::fprintf(stderr, "node 5: %s\n", node5.error().message().c_str());
        return 1;
    }
    auto guard5 = asio::make_work_guard(io5);
    std::thread t5([&] { io5.run(); });

    asio::io_context io1{1};
    plc::Plc plc1;
    server::ServerOptions o1;
    o1.port = 0;
    o1.node = 1;
    o1.tcp = false;
    o1.remotes.push_back(
        {0, 5, "127.0.0.1", tcp ? (*node5)->tcp_port() : (*node5)->udp_port(), tcp, 0});
    auto node1 = server::Server::start(io1, plc1, o1);
    if (!node1) {
        std::fprintf(stderr, "node 1: %s\n", node1.error().message().c_str());
        return 1;
    }
    server::InstructionRequest r;
    r.kind = *server::parse_instruction_kind(kind);
    r.destination = {0, 5, 0};
    r.local = *parse_address("D1000");
    r.remote = *parse_address("D2000");
    r.count = static_cast<std::uint16_t>(words);
    if (r.kind == server::InstructionKind::sendcmd)  // 01 01 D2000, `words` words
        r.command = {0x01,
                     0x01,
                     0x82,
                     0x07,
                     0xD0,
                     0x00,
                     static_cast<std::uint8_t>(words >> 8),
                     static_cast<std::uint8_t>(words & 0xFF)};
    r.options.timeout = 10;
    r.options.retries = 0;
    // Warm-up, untimed: one instruction at a time until one completes (up to 5 s), so a
    // FINS/TCP remote's connection is up before the clock starts (until then each one
    // ends at once with 0800/0101, not established).
    std::uint64_t warm_up_errors = 0;
    std::function<void()> warm_up;
    const auto warm_up_end = Clock::now() + std::chrono::seconds(5);
    warm_up = [&] {
        (*node1)->instructions().start(r, [&](const server::InstructionResult& result) {
            if (result.done() || Clock::now() >= warm_up_end) {
                io1.stop();
                return;
            }
            ++warm_up_errors;
            warm_up();
        });
    };
    asio::post(io1, warm_up);
    io1.run();
    io1.restart();
    if (warm_up_errors > 0)
        std::printf("warm-up: %llu instructions ended before the remote answered\n",
                    static_cast<unsigned long long>(warm_up_errors));
    const auto start = Clock::now();
    Runner runner{
        (*node1)->instructions(),
        r,
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)),
        0,
        0,
        0,
        [&] { (*node1)->stop(); }};
    asio::post(io1, [&] {
        for (unsigned i = 0; i < in_flight; ++i)
            runner.launch();
    });
    io1.run();  // ends when the last instruction completed after the deadline
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    guard5.reset();
    asio::post(io5, [&] { (*node5)->stop(); });
    t5.join();
    std::printf(
        "%s over %s, %u words, %u in flight: %.0f instructions/s (%llu done, %llu errors, %.2f "
        "s)\n",
        kind.c_str(), transport.c_str(), words, in_flight,
        static_cast<double>(runner.done) / elapsed, static_cast<unsigned long long>(runner.done),
        static_cast<unsigned long long>(runner.errors), elapsed);
    for (const auto& [what, n] : runner.why)
        std::printf("  error %s: %llu\n", what.c_str(), static_cast<unsigned long long>(n));
    return runner.errors == 0 ? 0 : 1;
}
