// finsd with [[plc]] tables: the plant (server/plant.hpp) on one I/O thread.
#include <csignal>
#include <cstdio>

#include <spdlog/spdlog.h>
#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include "cli/finsd/config_plant.hpp"
#include "server/router.hpp"
#include "server/server.hpp"

namespace fins::cli::finsd {

int serve_plant(const Settings& s) {
    spdlog::set_level(spdlog::level::from_str(s.log_level));
    std::signal(SIGXFSZ, SIG_IGN);
    server::PlantConfig config = s.plant;
    config.tcp_limits.handshake_timeout = std::chrono::seconds(s.tcp_handshake_timeout);
    config.tcp_limits.frame_timeout = std::chrono::seconds(s.tcp_frame_timeout);
    config.tcp_limits.idle_timeout = std::chrono::seconds(s.tcp_idle_timeout);
    config.tcp_limits.keepalive = std::chrono::seconds(s.tcp_keepalive);
    config.tcp_limits.max_pending = s.tcp_max_pending;
    if (const auto problem = server::validate_plant(config); !problem.empty()) {
        std::fprintf(stderr, "finsd: %s\n", problem.c_str());
        return 2;
    }
    asio::io_context io{1};
    auto plant = server::Plant::start(io, config);
    if (!plant) {
        std::fprintf(stderr, "finsd: cannot start the plant: %s\n",
                     plant.error().message().c_str());
        return 3;
    }
    asio::signal_set signals{io, SIGINT, SIGTERM};
    auto& router = (*plant)->router();
    for (std::size_t i = 0; i < router.port_count(); ++i) {
        const auto& p = router.port(i);
        spdlog::info("finsd: plc \"{}\" unit {} is FINS node {}.{}", s.plant.cpus[p.cpu].name,
                     p.unit_number, p.address.network, p.address.node);
    }
    auto& first = (*plant)->server(0, 0);
    const unsigned port = first.tcp_port() != 0 ? first.tcp_port() : first.udp_port();
    spdlog::info("finsd: plant of {} CPU Units, {} units", (*plant)->cpu_count(),
                 router.port_count());
    std::printf("listening %u\n", port);
    std::fflush(stdout);
    signals.async_wait([&](std::error_code, int signal) {
        spdlog::info("finsd: signal {}, shutting down", signal);
        (*plant)->stop();
        io.stop();
    });
    io.run();
    return 0;
}

}  // namespace fins::cli::finsd
