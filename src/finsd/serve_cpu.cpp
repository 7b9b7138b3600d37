// What finsd sets up beside each CPU Unit it serves, the single node's and each of a
// plant's alike (contract in serve_units.hpp).
#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

#include "finsd/config_plant.hpp"
#include "finsd/scenario_setup.hpp"
#include "finsd/serial_gateway_setup.hpp"
#include "finsd/serve_units.hpp"

namespace fins::finsd {

int report_failure(int code, const std::string& message) {
    std::fprintf(stderr, "finsd: %s\n", message.c_str());
    return code;
}

void Served::stop() {
    if (plant) plant->stop();  // every unit's sockets, then each state file flushed
    if (single_server) single_server->stop();
    if (single_plc) single_plc->storage().flush();
}

void CpuUnitExtras::stop() {
    for (auto& scenario : scenarios)
        if (scenario) scenario->stop();
    for (auto& of_cpu : schedules)
        for (auto& schedule : of_cpu)
            schedule->stop();
    for (auto& gateway : gateways)
        gateway->close_all();
    for (auto& ports : host_link)
        ports.stop();
}

namespace {

// The [[schedule]] check of a CPU Unit (config_schedule.hpp): its entries against its
// memory, and its FINS/TCP [[remote]]s within each unit's connection limit (W596 1-4).
Expected<void> check_cpu_schedule(const ServedCpu& cpu) {
    Settings check;
    check.schedule = *cpu.setup.schedule;
    check.remotes = *cpu.setup.remotes;
    check.max_connections = cpu.config->ports.front().max_connections;
    for (const auto& unit : cpu.config->ports)
        check.max_connections = std::min(check.max_connections, unit.max_connections);
    return check_schedule(check, cpu.plc->memory());
}

}  // namespace

int set_up_cpu(asio::io_context& io, const Served& served, std::size_t i, CpuUnitExtras& extras) {
    const ServedCpu& cpu = served.cpus[i];
    auto& plc = *cpu.plc;
    const auto& setup = cpu.setup;
    // A plant's errors name the [[plc]] table ("plc[1]: ..."); a single node's the key.
    const auto named = [&](const Error& e) {
        return served.is_plant() ? in_plant(e, "plc[" + std::to_string(i) + "]") : e;
    };
    // The memory table is checked against this CPU Unit's model; retained memory is left
    // alone when its state came from data_dir.
    if (auto r = check_initial_memory(*setup.memory, plc.memory()); !r)
        return report_failure(2, r.error());
    if (auto r = check_cpu_schedule(cpu); !r) return report_failure(2, named(r.error()));
    const auto written =
        apply_initial_memory(*setup.memory, plc.memory(), plc.storage().restored());
    if (!setup.memory->empty() && !served.is_plant())
        spdlog::info("finsd: {} [memory] entries written", written);
    // A line per CPU Unit at info for a plant a person reads; a site's go to debug.
    if (!setup.memory->empty() && served.is_plant())
        spdlog::log(
            served.cpus.size() <= units_logged_at_info ? spdlog::level::info : spdlog::level::debug,
            "finsd: plc \"{}\": {} memory entries written", cpu.name, written);
    apply_cpu_options(*setup.options, plc);  // [protection], [inject]

    // Serial Gateway ports (scuN.P / board.P in mode gateway) answer on every unit of the
    // CPU Unit. (The start's log lines come in this order: gateway ports, scenario, Host
    // Link ports.)
    auto gateways = std::make_unique<server::SerialPorts>();
    open_gateway_ports(io, *setup.serial, *gateways);
    for (auto* unit : cpu.units)
        unit->attach_serial_ports(gateways.get());
    extras.gateways.push_back(std::move(gateways));
    // [scenario]: compiled against this CPU Unit, its ticks handed over between the
    // io_context and finsd's scenario thread, its unit faults on every unit of the CPU
    // Unit. A plant's ticks spread over the period in groups (ScenarioRunner::phase_of).
    std::unique_ptr<scenario::Scenario> compiled;
    if (*setup.scenario) {
        auto c = compile_scenario(**setup.scenario, plc);
        if (!c) return report_failure(2, c.error());
        compiled = std::move(*c);
    }
    const auto phase = served.is_plant()
                           ? std::optional<double>(server::ScenarioRunner::phase_of(i))
                           : std::nullopt;
    extras.scenarios.push_back(
        run_scenario(io, *setup.scenario, std::move(compiled), plc, phase, extras.scenario_worker));
    if (extras.scenarios.back())
        for (auto* unit : cpu.units)
            unit->dispatcher().attach_faults(extras.scenarios.back().get());

    // The Host Link slave ports talk to the CPU Unit through its first unit (frames for
    // other networks are routed from there, as from any unit).
    extras.host_link.emplace_back();
    if (auto r = start_serial_ports(io, cpu.units.front()->dispatcher(), *setup.serial,
                                    extras.host_link.back());
        !r)
        return report_failure(2, named(r.error()));

    // [[schedule]]: each scheduled instruction leaves through the unit its destination
    // network is reached by (the CPU Unit's routing tables; a single node's one unit).
    // Each entry's unit and place there, so that `finsd ctl instructions` lists every
    // entry's counters in the configuration's order, whichever unit runs it.
    std::vector<std::vector<server::ScheduledInstruction>> by_unit(cpu.units.size());
    std::vector<std::pair<std::size_t, std::size_t>> placed;
    for (const auto& e : *setup.schedule) {
        const auto k = server::unit_toward(*cpu.config, e.scheduled.request.destination.network);
        placed.emplace_back(k, by_unit[k].size());
        by_unit[k].push_back(e.scheduled);
    }
    extras.schedules.emplace_back();
    std::vector<const server::InstructionSchedule*> of_unit(cpu.units.size(), nullptr);
    for (std::size_t k = 0; k < by_unit.size(); ++k) {
        if (by_unit[k].empty()) continue;
        extras.schedules.back().push_back(std::make_unique<server::InstructionSchedule>(
            io.get_executor(), cpu.units[k]->instructions(), std::move(by_unit[k])));
        extras.schedules.back().back()->start();
        of_unit[k] = extras.schedules.back().back().get();
    }
    auto& entries = extras.schedule_entries.emplace_back();
    for (const auto& [k, index] : placed)
        entries.push_back({of_unit[k], index});
    return -1;
}

}  // namespace fins::finsd
