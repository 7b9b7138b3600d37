// finsd with [[plc]] tables opened (contract in serve_units.hpp): the plant
// (server/routing/plant.hpp) of settings.plant on finsd's one I/O thread, every CPU Unit
// on its state file with its units bound. What each CPU Unit has beyond its units is set
// up as for a single node (serve_cpu.cpp).
#ifndef _WIN32
#include <sys/resource.h>
#endif

#include <algorithm>
#include <string>

#include <spdlog/spdlog.h>

#include "finsd/config_plant.hpp"
#include "finsd/serial_gateway_setup.hpp"
#include "finsd/serve_units.hpp"
#include "plc/profile.hpp"
#include "server/routing/router.hpp"

namespace fins::finsd {

namespace {

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

}  // namespace

int open_plant(asio::io_context& io, const Settings& s, Served& served) {
    if (const auto problem = plant_config(s, served.config); !problem.empty())
        return report_failure(2, problem);
    warn_single_node_keys(s);
    raise_descriptor_limit(server::plant_descriptors(served.config));
    auto plant = server::Plant::start(io, served.config);
    if (!plant) return report_failure(3, "cannot start the plant: " + plant.error().message());
    served.plant = std::move(*plant);
    auto& p = *served.plant;
    served.cpus.resize(p.cpu_count());
    static const Settings::PlantCpuSettings none;  // (the loader gives each [[plc]] one)
    for (std::size_t i = 0; i < served.cpus.size(); ++i) {
        auto& cpu = served.cpus[i];
        const auto& extra = i < s.plant_cpu.size() ? s.plant_cpu[i] : none;
        cpu.plc = &p.plc(i);
        cpu.name = served.config.cpus[i].name;
        cpu.config = &served.config.cpus[i];
        for (std::size_t k = 0; k < cpu.config->ports.size(); ++k)
            cpu.units.push_back(&p.server(i, k));
        cpu.setup = {&extra,          &extra.memory,   &extra.serial,
                     &extra.schedule, &extra.scenario, &cpu.config->remotes};
    }
    return -1;
}

}  // namespace fins::finsd
