// The CPU Units finsd serves, whichever way they were opened (serve.hpp): the single
// node is one CPU Unit with one Ethernet unit (serve_single.cpp), a plant is the CPU
// Units of its [[plc]] tables with their [[plc.ethernet]] units (serve_plant.cpp). Once
// open, serve.cpp gives every CPU Unit the same set-up (set_up_cpu, serve_cpu.cpp) and
// runs them all under one control channel, one web front, one signal handling and one
// check of every state file.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "finsd/config.hpp"
#include "finsd/serial_ports.hpp"
#include "plc/plc.hpp"
#include "server/control/control.hpp"
#include "server/instructions/instruction_schedule.hpp"
#include "server/routing/plant.hpp"
#include "server/scenario/scenario_runner.hpp"
#include "server/serial/serial_ports.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::finsd {

// What finsd sets up beside a CPU Unit's Ethernet units: the single node's top-level
// tables, or a [[plc]]'s own (Settings::PlantCpuSettings).
struct CpuUnitSetup {
    const CpuUnitOptions* options = nullptr;                // [protection], [inject]
    const std::vector<MemoryInit>* memory = nullptr;        // [memory]
    const std::vector<SerialPortConfig>* serial = nullptr;  // [serial], --serial
    const std::vector<ScheduleEntry>* schedule = nullptr;   // [[schedule]]
    const std::optional<ScenarioConfig>* scenario = nullptr;
    const std::vector<server::RemoteNode>* remotes = nullptr;  // [[remote]]
};

struct ServedCpu {
    plc::Plc* plc = nullptr;
    std::string name;                                // its [[plc]] name; "" for a single node
    const server::PlantCpuConfig* config = nullptr;  // its units and relays (unit_toward)
    std::vector<server::Server*> units;              // one per Ethernet unit, in order
    CpuUnitSetup setup;
};

// The CPU Units and what owns them: a single node's Plc and Server, or the Plant.
struct Served {
    std::vector<ServedCpu> cpus;
    server::PlantConfig config;  // the plant's; a single node's one CPU Unit and unit
    std::unique_ptr<plc::Plc> single_plc;
    std::unique_ptr<server::Server> single_server;
    std::unique_ptr<server::Plant> plant;

    [[nodiscard]] bool is_plant() const noexcept { return plant != nullptr; }
    // Closes every socket and flushes every state file (the single node's, or the plant's).
    void stop();
};

// Opens the single node of the top-level keys: its state file, Plc, operating mode, file
// memory and Server. -1, or finsd's exit code (the reason printed).
int open_single(asio::io_context& io, const Settings& settings, Served& served);

// Opens the plant of settings.plant (server::Plant::start): every CPU Unit's state file,
// Plc, mode, file memory, routing tables and units. -1, or finsd's exit code.
int open_plant(asio::io_context& io, const Settings& settings, Served& served);

// What runs beside the CPU Units; stopped before them.
struct CpuUnitExtras {
    // finsd's scenario thread (declared first: it outlives the runners).
    std::unique_ptr<server::ScenarioWorker> scenario_worker;
    std::vector<std::unique_ptr<server::SerialPorts>> gateways;
    std::vector<SerialPorts> host_link;
    // Per CPU Unit, in the order of Served::cpus: its [[schedule]] runs on each unit that
    // sends some of it (a single node: its one unit); its scenario, or null.
    std::vector<std::vector<std::unique_ptr<server::InstructionSchedule>>> schedules;
    // Per CPU Unit: its [[schedule]] entries in the configuration's order (ControlTarget).
    std::vector<std::vector<server::ScheduleEntry>> schedule_entries;
    std::vector<std::unique_ptr<server::ScenarioRunner>> scenarios;

    void stop();
};

// CPU Unit `i` of `served` gets its memory table, protections and injections, scenario,
// serial ports and scheduled network instructions. -1, or finsd's exit code.
int set_up_cpu(asio::io_context& io, const Served& served, std::size_t i, CpuUnitExtras& extras);

// Above this many units the lines for each ("unit N is FINS node ...", "N memory
// entries written") are logged at debug level.
inline constexpr std::size_t units_logged_at_info = 64;

// finsd's one way to print a start-up failure: "finsd: <message>" on stderr, whatever
// the log level. Returns `code`.
int report_failure(int code, const std::string& message);

}  // namespace fins::finsd
