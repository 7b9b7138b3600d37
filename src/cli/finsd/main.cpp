// finsd: a virtual Omron CS/CJ CPU Unit answering FINS over UDP and TCP.
//
// Exit codes: 0 clean shutdown (SIGINT/SIGTERM), 2 usage error, 3 could not bind.
#include <csignal>
#include <cstdio>
#include <string>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "server/server.hpp"

int main(int argc, char** argv) {
    CLI::App app{"finsd: a virtual Omron CS/CJ CPU Unit speaking FINS/UDP and FINS/TCP"};
    fins::server::ServerOptions options;
    unsigned node = 0;
    unsigned network = 0;
    bool no_udp = false;
    bool no_tcp = false;
    std::string log_level = "info";
    app.add_option("--bind", options.bind_address, "Address to listen on (IPv4 or IPv6)")
        ->capture_default_str();
    app.add_option("--port", options.port, "UDP and TCP port (0 = any free port)")
        ->capture_default_str();
    app.add_option("--node", node,
                   "FINS node address 1-254 (default: last octet of --bind, 1 on loopback)")
        ->check(CLI::Range(1, 254));
    app.add_option("--network", network, "FINS network address 0-127 (0 = local network)")
        ->check(CLI::Range(0, 127));
    app.add_option("--max-connections", options.max_tcp_connections,
                   "Maximum FINS/TCP connections (W596: 16)")
        ->capture_default_str()
        ->check(CLI::Range(1, 254));
    app.add_flag("--no-udp", no_udp, "Do not serve FINS/UDP");
    app.add_flag("--no-tcp", no_tcp, "Do not serve FINS/TCP");
    app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
        ->capture_default_str()
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int rc = app.exit(e);
        return rc == 0 ? 0 : 2;
    }
    if (no_udp && no_tcp) {
        std::fprintf(stderr, "finsd: --no-udp and --no-tcp leave nothing to serve\n");
        return 2;
    }
    options.udp = !no_udp;
    options.tcp = !no_tcp;
    options.node = static_cast<std::uint8_t>(node);
    options.network = static_cast<std::uint8_t>(network);
    spdlog::set_level(spdlog::level::from_str(log_level));

    fins::plc::Plc plc{fins::plc::cj2h()};
    asio::io_context io{1};
    auto server = fins::server::Server::start(io, plc, options);
    if (!server) {
        std::fprintf(stderr, "finsd: cannot listen on %s port %u: %s\n",
                     options.bind_address.c_str(), static_cast<unsigned>(options.port),
                     server.error().message().c_str());
        return 3;
    }
    const auto self = (*server)->address();
    spdlog::info("finsd: {} on {} port {} (UDP {}, TCP {}), FINS address {}.{}.{}",
                 plc.profile().model, options.bind_address,
                 (*server)->tcp_port() != 0 ? (*server)->tcp_port() : (*server)->udp_port(),
                 options.udp ? "on" : "off", options.tcp ? "on" : "off", self.network, self.node,
                 self.unit);
    // A line on stdout that scripts and tests can wait for: "listening <port>".
    std::printf("listening %u\n",
                static_cast<unsigned>((*server)->tcp_port() != 0 ? (*server)->tcp_port()
                                                                 : (*server)->udp_port()));
    std::fflush(stdout);

    asio::signal_set signals{io, SIGINT, SIGTERM};
    signals.async_wait([&](std::error_code, int signal) {
        spdlog::info("finsd: signal {}, shutting down", signal);
        (*server)->stop();
        io.stop();
    });
    io.run();
    return 0;
}
