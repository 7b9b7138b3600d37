// finsd with [[plc]] tables: the plant (server/routing/plant.hpp) on one I/O thread.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <string>

#include <spdlog/spdlog.h>
#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include "cli/finsd/config_plant.hpp"
#include "cli/finsd/control_setup.hpp"
#include "plc/injections.hpp"
#include "server/control/control.hpp"
#include "server/routing/router.hpp"
#include "server/sessions/server.hpp"

namespace fins::cli::finsd {

int serve_plant(const Settings& s) {
    spdlog::set_level(spdlog::level::from_str(s.log_level));
    std::signal(SIGXFSZ, SIG_IGN);
    server::PlantConfig config = s.plant;
    config.reset_state = s.reset_state;
    config.tcp_limits.handshake_timeout = std::chrono::seconds(s.tcp_handshake_timeout);
    config.tcp_limits.frame_timeout = std::chrono::seconds(s.tcp_frame_timeout);
    config.tcp_limits.idle_timeout = std::chrono::seconds(s.tcp_idle_timeout);
    config.tcp_limits.keepalive = std::chrono::seconds(s.tcp_keepalive);
    config.tcp_limits.max_pending = s.tcp_max_pending;
    if (const auto problem = server::validate_plant(config); !problem.empty()) {
        std::fprintf(stderr, "finsd: %s\n", problem.c_str());
        return 2;
    }
    // The single node's keys and flags describe no unit of the plant: say so rather than
    // let someone believe they took effect.
    const Settings single;
    std::string ignored;
    const auto note = [&](bool set, const char* what) {
        if (set) ignored += std::string(ignored.empty() ? "" : ", ") + what;
    };
    note(s.profile != single.profile, "profile");
    note(s.bind != single.bind, "bind");
    note(s.port != single.port, "port");
    note(s.node != single.node, "node");
    note(s.network != single.network, "network");
    note(s.data_dir.has_value(), "data_dir");
    note(!s.memory.empty(), "[memory] (a [[plc]] takes a memory table of its own)");
    const bool injects = s.inject.battery_error || !s.inject.fal.empty() ||
                         s.inject.fals.has_value() || !s.inject.errors.empty() ||
                         std::any_of(s.inject.messages.begin(), s.inject.messages.end(),
                                     [](const auto& m) { return m.has_value(); });
    note(injects, "[inject] (a [[plc]] takes its own)");
    note(s.network_write_protection.mode != single.network_write_protection.mode ||
             s.um_read_protection || s.dip_write_protection || !s.um_password.empty(),
         "[protection] (a [[plc]] takes its own)");
    if (!ignored.empty())
        spdlog::warn(
            "finsd: {} set for a single node: a plant ([[plc]]) sets them per CPU "
            "Unit and unit, so they are ignored",
            ignored);
    asio::io_context io{1};
    auto plant = server::Plant::start(io, config);
    if (!plant) {
        std::fprintf(stderr, "finsd: cannot start the plant: %s\n",
                     plant.error().message().c_str());
        return 3;
    }
    // Each [[plc]]'s memory table, as [memory] is for a single node: checked against that
    // CPU Unit's model; retained memory is left alone when its state came from data_dir.
    for (std::size_t i = 0; i < s.plant_cpu.size() && i < (*plant)->cpu_count(); ++i) {
        auto& plc = (*plant)->plc(i);
        const auto& cpu = s.plant_cpu[i];
        const auto& entries = cpu.memory;
        if (auto r = check_initial_memory(entries, plc.memory()); !r) {
            std::fprintf(stderr, "finsd: %s\n", r.error().c_str());
            return 2;
        }
        const auto written = apply_initial_memory(entries, plc.memory(), plc.storage().restored());
        if (!entries.empty())
            spdlog::info("finsd: plc \"{}\": {} memory entries written", s.plant.cpus[i].name,
                         written);
        apply_cpu_options(cpu, plc);  // [plc.protection], [plc.inject]
    }
    // The control channel (`finsd ctl --plc NAME|NET.NODE`) drives every [[plc]]; the
    // first without --plc (control_setup.hpp).
    std::vector<server::ControlTarget> targets((*plant)->cpu_count());
    for (std::size_t i = 0; i < targets.size(); ++i) {
        targets[i].plc = &(*plant)->plc(i);
        targets[i].name = s.plant.cpus[i].name;
    }
    for (std::size_t i = 0; i < (*plant)->router().port_count(); ++i) {
        const auto& p = (*plant)->router().port(i);
        targets[p.cpu].addresses.emplace_back(p.address.network, p.address.node);
    }
    auto control_start = start_control(io, std::move(targets), s.control_socket);
    if (control_start.exit_code >= 0) {
        std::fprintf(stderr, "finsd: %s\n", control_start.error.c_str());
        return control_start.exit_code;
    }
    auto& control = control_start.server;
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
        if (control) control->stop();
        io.stop();
    });
    io.run();
    return 0;
}

}  // namespace fins::cli::finsd
