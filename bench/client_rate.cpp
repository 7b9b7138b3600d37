// fins_client_rate: the C++ side of bench/python_client.py. Sends 1-word MEMORY AREA
// READs through fins::Client (the same library the finskit Python module wraps) to a
// running finsd for a fixed time, keeping N in flight, and prints "<requests> <seconds>".
//   fins_client_rate HOST PORT udp|tcp IN_FLIGHT SECONDS
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string_view>

#include "fins/client.hpp"
#include "fins/commands/memory_area.hpp"

int main(int argc, char** argv) {
    if (argc != 6) {
        std::fprintf(stderr, "usage: fins_client_rate HOST PORT udp|tcp IN_FLIGHT SECONDS\n");
        return 2;
    }
    fins::ClientOptions options;
    options.host = argv[1];
    options.port = static_cast<std::uint16_t>(std::atoi(argv[2]));
    if (std::string_view{argv[3]} == "tcp") options.protocol = fins::ClientOptions::Protocol::tcp;
    const int in_flight = std::atoi(argv[4]);
    const auto duration = std::chrono::duration<double>(std::atof(argv[5]));
    auto client = fins::Client::connect(options);
    if (!client || in_flight < 1 || in_flight > 256) return 3;
    fins::MemoryAreaRead read;
    read.start = fins::to_memory_address(fins::parse_address("D0").value()).value();
    read.count = 1;
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const auto end = start + duration;
    long done = 0;
    bool failed = false;
    std::function<void()> issue = [&] {
        (*client)->async_send(read, [&](fins::Result<fins::MemoryAreaReadResponse> r) {
            if (!r) failed = true;
            ++done;
            if (!failed && Clock::now() < end) issue();
        });
    };
    for (int i = 0; i < in_flight; ++i)
        issue();
    (*client)->run();
    const std::chrono::duration<double> took = Clock::now() - start;
    std::printf("%ld %.6f\n", done, took.count());
    return failed ? 1 : 0;
}
