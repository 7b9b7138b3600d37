// finsd's single node opened (contract in serve_units.hpp): the top-level keys as one
// CPU Unit with one Ethernet unit, in the order a plant opens each of its CPU Units
// (server/routing/plant.hpp): state file -> Plc -> mode -> file memory -> Server.
#include <chrono>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "finsd/config_plant.hpp"
#include "finsd/serial_gateway_setup.hpp"
#include "finsd/serve_units.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::finsd {

namespace {}  // namespace

int open_single(asio::io_context& io, const Settings& s, Served& served) {
    plc::Profile profile = *plc::find_profile(s.profile);
    if (s.dip_write_protection) profile.dip_switch |= plc::dip_pin1;
    if (auto r = mount_serial_units(s.serial, profile); !r) return report_failure(2, r.error());

    // A state file refused, moved aside or not stopped cleanly: said as for a plant's CPU Unit.
    auto opened = server::open_cpu_state(profile, s.data_dir, {s.durability}, s.reset_state, "");
    if (!opened) return report_failure(3, opened.error().message);
    served.single_plc = std::move(*opened);
    plc::Plc& plc = *served.single_plc;
    const bool restored = plc.storage().restored();
    if (s.data_dir)
        spdlog::info("finsd: {} state file {}", restored ? "restored" : "new",
                     plc.storage().path().string());
    plc.change_mode(s.mode, std::chrono::system_clock::now());
    // File memory (22 xx): <data_dir>/card and <data_dir>/em; else a temp dir removed at exit.
    if (const auto refused = server::set_up_file_memory(plc, s, s.data_dir, ""))
        return report_failure(3, refused->message);

    // The same translation as each unit of a plant gets (server/routing/plant.hpp).
    server::PlantCpuConfig one;
    one.profile = s.profile;
    one.mode = s.mode;
    one.data_dir = s.data_dir;
    one.durability = s.durability;
    one.ports.push_back(single_unit(s));
    one.remotes = s.remotes;
    served.config.cpus.push_back(std::move(one));
    auto options = server::options_for(served.config.cpus[0].ports[0], tcp_limits(s));
    options.remotes = s.remotes;
    auto server = server::Server::start(io, plc, options);
    if (!server)
        return report_failure(3, "cannot listen on " + s.bind + " port " + std::to_string(s.port) +
                                     ": " + server.error().message());
    served.single_server = std::move(*server);

    ServedCpu cpu;
    cpu.plc = &plc;
    cpu.config = &served.config.cpus[0];
    cpu.units.push_back(served.single_server.get());
    cpu.setup = {&s, &s.memory, &s.serial, &s.schedule, &s.scenario, &s.remotes};
    served.cpus.push_back(std::move(cpu));
    return -1;
}

}  // namespace fins::finsd
