// finsd with [[plc]] tables: the plant (server/routing/plant.hpp) on one I/O thread, and
// what each CPU Unit has beyond its units: memory table, protections, injections, serial
// ports and scheduled network instructions, set up as finsd sets them up for one node.
#ifndef _WIN32
#include <sys/resource.h>
#endif

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>

#include "finsd/config_plant.hpp"
#include "finsd/control_setup.hpp"
#include "finsd/process_os.hpp"
#include "finsd/scenario_setup.hpp"
#include "finsd/serial_gateway_setup.hpp"
#include "finsd/serial_ports.hpp"
#include "finsd/web_setup.hpp"
#include "plc/injections.hpp"
#include "plc/profile.hpp"
#include "server/control/control.hpp"
#include "server/instructions/instruction_schedule.hpp"
#include "server/routing/router.hpp"
#include "server/serial/serial_ports.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::finsd {

namespace {

int fail(int code, const std::string& message) {
    std::fprintf(stderr, "finsd: %s\n", message.c_str());
    return code;
}

// Above this many units (CPU Units) the lines for each ("unit N is FINS node ...", "N
// memory entries written") are logged at debug level.
constexpr std::size_t units_logged_at_info = 64;

// The plant keeps a socket or two per unit open (server::plant_descriptors): the soft
// limit on open files goes up to the hard one when the plant needs more than it allows
// (a shell's 1,024 is a plant of ~480 units). Plant::start refuses what still does not fit.
#ifdef _WIN32
// Windows has no limit on open sockets to raise (a SOCKET is a kernel handle).
void raise_descriptor_limit(std::size_t) {}
#else
void raise_descriptor_limit(std::size_t needed) {
    rlimit limit{};
    if (::getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return;
    if (needed + server::descriptor_reserve <= limit.rlim_cur || limit.rlim_cur >= limit.rlim_max)
        return;
    const rlim_t was = limit.rlim_cur;
    limit.rlim_cur = limit.rlim_max;
    if (::setrlimit(RLIMIT_NOFILE, &limit) == 0)
        spdlog::info("finsd: open files limit raised from {} to {} for the plant's sockets", was,
                     limit.rlim_cur);
}
#endif

std::string plc_path(std::size_t cpu) {
    return "plc[" + std::to_string(cpu) + "]";
}

// The single node's keys and flags that describe no unit of the plant: say so rather
// than let someone believe they took effect.
void warn_single_node_keys(const Settings& s) {
    const Settings single;
    std::string ignored;
    const auto note = [&](bool set, const char* what) {
        if (set) ignored += std::string(ignored.empty() ? "" : ", ") + what;
    };
    note(s.profile != single.profile, "profile");
    note(s.bind != single.bind, "bind");
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
    note(s.durability != single.durability, "[storage] durability (a [[plc]] takes its own)");
    note(s.card_kbytes || s.em_file_bank || s.cassette,
         "[files] (a [[plc]] takes its own [plc.files])");
    note(!s.serial.empty(), "[serial] and --serial (a [[plc]] takes its own [plc.serial])");
    note(!s.remotes.empty(), "[[remote]] (a [[plc]] takes its own [[plc.remote]])");
    note(!s.schedule.empty(), "[[schedule]] (a [[plc]] takes its own [[plc.schedule]])");
    if (!ignored.empty())
        spdlog::warn(
            "finsd: {} set for a single node: a plant ([[plc]]) sets them per CPU "
            "Unit and unit, so they are ignored",
            ignored);
}

// The plant's configuration from the settings: the [network] TCP limits for every unit,
// the port (--port, [network] port) for each unit without a port of its own, and the
// units of each CPU Unit's Serial Gateway ports. Empty, or the error.
std::string plant_config(const Settings& s, server::PlantConfig& config) {
    config = s.plant;
    config.reset_state = s.reset_state;
    config.tcp_limits = tcp_limits(s);
    for (std::size_t i = 0; i < config.cpus.size() && i < s.plant_cpu.size(); ++i) {
        auto& cpu = config.cpus[i];
        const auto& extra = s.plant_cpu[i];
        for (std::size_t k = 0; k < cpu.ports.size() && k < extra.port_given.size(); ++k)
            if (!extra.port_given[k]) cpu.ports[k].port = s.port;
    }
    if (auto problem = server::validate_plant(config); !problem.empty()) return problem;
    for (std::size_t i = 0; i < config.cpus.size() && i < s.plant_cpu.size(); ++i) {
        auto& cpu = config.cpus[i];
        if (s.plant_cpu[i].serial.empty()) continue;
        plc::Profile profile = *plc::find_profile(cpu.profile);
        if (auto r = mount_serial_units(s.plant_cpu[i].serial, profile); !r)
            return in_plant(r.error(), plc_path(i) + ".serial");
        cpu.units = profile.units;
    }
    return {};
}

// What runs beside the plant for its CPU Units; stopped before the plant.
struct CpuUnitExtras {
    // finsd's scenario thread (declared first: it outlives the runners).
    std::unique_ptr<server::ScenarioWorker> scenario_worker;
    std::vector<std::unique_ptr<server::SerialPorts>> gateways;
    std::vector<SerialPorts> host_link;
    std::vector<std::unique_ptr<server::InstructionSchedule>> schedules;
    std::vector<std::unique_ptr<server::ScenarioRunner>> scenarios;  // per CPU Unit, or null

    void stop() {
        for (auto& scenario : scenarios)
            if (scenario) scenario->stop();
        for (auto& schedule : schedules)
            schedule->stop();
        for (auto& gateway : gateways)
            gateway->close_all();
        for (auto& ports : host_link)
            ports.stop();
    }
};

// CPU Unit `i` of the plant gets its memory table, options, serial ports and schedule.
// -1, or finsd's exit code.
int set_up_cpu(asio::io_context& io, const Settings& s, server::Plant& plant, std::size_t i,
               CpuUnitExtras& extras) {
    auto& plc = plant.plc(i);
    const auto& cpu = s.plant_cpu[i];
    const auto& config = s.plant.cpus[i];
    // The memory table as [memory] is for a single node: checked against that CPU Unit's
    // model; retained memory is left alone when its state came from data_dir.
    if (auto r = check_initial_memory(cpu.memory, plc.memory()); !r) return fail(2, r.error());
    Settings scheduled;
    scheduled.schedule = cpu.schedule;
    if (auto r = check_schedule(scheduled, plc.memory()); !r)
        return fail(2, in_plant(r.error(), plc_path(i)));
    const auto written = apply_initial_memory(cpu.memory, plc.memory(), plc.storage().restored());
    // A line per CPU Unit at info for a plant a person reads; a site's go to debug.
    if (!cpu.memory.empty())
        spdlog::log(
            plant.cpu_count() <= units_logged_at_info ? spdlog::level::info : spdlog::level::debug,
            "finsd: plc \"{}\": {} memory entries written", config.name, written);
    apply_cpu_options(cpu, plc);  // [plc.protection], [plc.inject]
    // [plc.scenario]: compiled against this CPU Unit, its ticks handed over between the
    // io_context and the plant's scenario thread, its unit faults on every unit of the
    // CPU Unit.
    std::unique_ptr<scenario::Scenario> compiled;
    if (cpu.scenario) {
        auto c = compile_scenario(*cpu.scenario, plc);
        if (!c) return fail(2, c.error());
        compiled = std::move(*c);
    }
    // The plant's ticks spread over the period in groups (ScenarioRunner::phase_of).
    extras.scenarios.push_back(run_scenario(io, cpu.scenario, std::move(compiled), plc,
                                            server::ScenarioRunner::phase_of(i),
                                            extras.scenario_worker));
    for (std::size_t k = 0; k < config.ports.size() && extras.scenarios.back(); ++k)
        plant.server(i, k).dispatcher().attach_faults(extras.scenarios.back().get());

    // Serial Gateway ports answer on every unit of the CPU Unit; the Host Link slave
    // ports talk to the CPU Unit through its first unit (frames for other networks are
    // routed from there, as from any unit).
    auto gateways = std::make_unique<server::SerialPorts>();
    open_gateway_ports(io, cpu.serial, *gateways);
    for (std::size_t k = 0; k < config.ports.size(); ++k)
        plant.server(i, k).attach_serial_ports(gateways.get());
    extras.gateways.push_back(std::move(gateways));
    extras.host_link.emplace_back();
    if (auto r = start_serial_ports(io, plant.server(i, 0).dispatcher(), cpu.serial,
                                    extras.host_link.back());
        !r)
        return fail(2, in_plant(r.error(), plc_path(i)));

    // Each scheduled instruction leaves through the unit its destination network is
    // reached by (the CPU Unit's routing tables).
    std::vector<std::vector<server::ScheduledInstruction>> by_unit(config.ports.size());
    for (const auto& e : cpu.schedule)
        by_unit[server::unit_toward(config, e.scheduled.request.destination.network)].push_back(
            e.scheduled);
    for (std::size_t k = 0; k < by_unit.size(); ++k) {
        if (by_unit[k].empty()) continue;
        extras.schedules.push_back(std::make_unique<server::InstructionSchedule>(
            io.get_executor(), plant.server(i, k).instructions(), std::move(by_unit[k])));
        extras.schedules.back()->start();
    }
    return -1;
}

}  // namespace

int serve_plant(const Settings& s) {
    spdlog::set_level(spdlog::level::from_str(s.log_level));
    ignore_file_size_signal();
    server::PlantConfig config;
    if (const auto problem = plant_config(s, config); !problem.empty()) return fail(2, problem);
    warn_single_node_keys(s);
    raise_descriptor_limit(server::plant_descriptors(config));
    asio::io_context io{1};
    auto plant = server::Plant::start(io, config);
    if (!plant) return fail(3, "cannot start the plant: " + plant.error().message());
    CpuUnitExtras extras;
    for (std::size_t i = 0; i < s.plant_cpu.size() && i < (*plant)->cpu_count(); ++i)
        if (const int rc = set_up_cpu(io, s, **plant, i, extras); rc >= 0) {
            extras.stop();
            return rc;
        }
    // The control channel (`finsd ctl --plc NAME|NET.NODE`) drives every [[plc]]; the
    // first without --plc (control_setup.hpp).
    std::vector<server::ControlTarget> targets((*plant)->cpu_count());
    for (std::size_t i = 0; i < targets.size(); ++i) {
        targets[i].plc = &(*plant)->plc(i);
        targets[i].name = s.plant.cpus[i].name;
        // send / recv / sendcmd leave through the CPU Unit's first unit.
        targets[i].instructions = &(*plant)->server(i, 0).instructions();
        if (i < extras.scenarios.size()) targets[i].scenario = extras.scenarios[i].get();
    }
    for (std::size_t i = 0; i < (*plant)->router().port_count(); ++i) {
        const auto& p = (*plant)->router().port(i);
        targets[p.cpu].addresses.emplace_back(p.address.network, p.address.node);
    }
    // --http (docs/web.md): every CPU Unit, each with its first unit's server.
    std::vector<const server::Server*> first_units;
    for (std::size_t i = 0; i < targets.size(); ++i)
        first_units.push_back(&(*plant)->server(i, 0));
    auto web = start_web(io, s.http, targets, first_units, plant->get());
    if (web.exit_code >= 0) {
        extras.stop();
        std::fprintf(stderr, "finsd: %s\n", web.error.c_str());
        return web.exit_code;
    }
    auto control_start = start_control(io, std::move(targets), s.control_socket);
    if (control_start.exit_code >= 0) {
        extras.stop();
        std::fprintf(stderr, "finsd: %s\n", control_start.error.c_str());
        return control_start.exit_code;
    }
    auto& control = control_start.server;
    asio::signal_set signals{io, SIGINT, SIGTERM};
    auto& router = (*plant)->router();
    // A line per unit at info for a plant a person reads; a site's 10,000 go to debug.
    const auto unit_level =
        router.port_count() <= units_logged_at_info ? spdlog::level::info : spdlog::level::debug;
    if (spdlog::should_log(unit_level))
        for (std::size_t i = 0; i < config.cpus.size(); ++i)
            for (std::size_t k = 0; k < config.cpus[i].ports.size(); ++k) {
                auto& server = (*plant)->server(i, k);
                const auto self = server.address();
                spdlog::log(unit_level,
                            "finsd: plc \"{}\" unit {} is FINS node {}.{} on {} port {}",
                            config.cpus[i].name, config.cpus[i].ports[k].unit_number, self.network,
                            self.node, config.cpus[i].ports[k].bind,
                            server.tcp_port() != 0 ? server.tcp_port() : server.udp_port());
            }
    auto& first = (*plant)->server(0, 0);
    const unsigned port = first.tcp_port() != 0 ? first.tcp_port() : first.udp_port();
    spdlog::info("finsd: plant of {} CPU Units, {} units{}", (*plant)->cpu_count(),
                 router.port_count(),
                 unit_level == spdlog::level::info ? "" : " (a line per unit at debug level)");
    std::printf("listening %u\n", port);
    std::fflush(stdout);
    signals.async_wait([&](std::error_code, int signal) {
        spdlog::info("finsd: signal {}, shutting down", signal);
        extras.stop();
        (*plant)->stop();
        if (control) control->stop();
        if (web.server) web.server->stop();
        io.stop();
    });
    io.run();
    return 0;
}

}  // namespace fins::finsd
