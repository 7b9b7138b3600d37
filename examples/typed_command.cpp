// Sends typed commands with Client::send<C>(): CPU UNIT STATUS READ (06 01) and CLOCK
// READ (07 01). Each command is a struct; its Response type is decoded for you.
//   typed_command [HOST] [PORT]
#include <cstdio>
#include <cstdlib>

#include <fins/client.hpp>
#include <fins/commands/clock.hpp>
#include <fins/commands/diagnostics.hpp>

int main(int argc, char** argv) {
    fins::ClientOptions options;
    if (argc > 1) options.host = argv[1];
    if (argc > 2) options.port = static_cast<std::uint16_t>(std::atoi(argv[2]));
    auto client = fins::Client::connect(options);
    if (!client) {
        std::fprintf(stderr, "connect: %s\n", client.error().message().c_str());
        return 3;
    }
    const auto status = (*client)->send(fins::CpuUnitStatusRead{});
    if (!status) {
        std::fprintf(stderr, "06 01: %s\n", status.error().message().c_str());
        return 4;
    }
    const char* mode = status->mode == fins::mode_run       ? "RUN"
                       : status->mode == fins::mode_monitor ? "MONITOR"
                                                            : "PROGRAM";
    std::printf("status: %s, mode %s, fatal errors %04X\n",
                status->running() ? "running" : "stopped", mode, status->fatal_errors);
    const auto clock = (*client)->send(fins::ClockRead{});
    if (!clock) {
        std::fprintf(stderr, "07 01: %s\n", clock.error().message().c_str());
        return 4;
    }
    const auto& t = clock->time;
    std::printf("clock: %04d-%02u-%02u %02u:%02u:%02u\n", fins::full_year(t.year), t.month, t.day,
                t.hour, t.minute, t.second);
    return 0;
}
