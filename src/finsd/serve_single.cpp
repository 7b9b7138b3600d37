// finsd's single node opened (contract in serve_units.hpp): the top-level keys as one
// CPU Unit with one Ethernet unit, in the order a plant opens each of its CPU Units
// (server/routing/plant.hpp): state file -> Plc -> mode -> file memory -> Server.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "finsd/config_plant.hpp"
#include "finsd/serial_gateway_setup.hpp"
#include "finsd/serve_units.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"
#include "plc/storage/storage_format.hpp"

namespace fins::finsd {

namespace {

// The profile a foreign state file was written for, to name it in the refusal: the
// header holds the profile name NUL-terminated (plc/storage/storage.cpp), so look for
// each known name there rather than depend on the header's offsets.
std::string state_file_profile(const std::filesystem::path& dir) {
    std::ifstream f(dir / "finsd.state", std::ios::binary);
    std::string head(4096, '\0');
    f.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(f.gcount()));
    for (const auto& p : plc::profiles())
        if (head.find(std::string(1, '\0') + p.name + std::string(1, '\0')) != std::string::npos)
            return p.name;
    return "unknown";
}

// The PLC on its state file (or the heap) into `plc` (plc::open_plc); -1, or the exit
// code. A state file refused for its content stops finsd unless --reset-state.
int open_plc(const Settings& s, const plc::Profile& profile, std::unique_ptr<plc::Plc>& plc) {
    using plc::Storage;
    auto opened = plc::open_plc(profile, s.data_dir, {s.durability}, s.reset_state);
    const std::string file =
        s.data_dir ? (*s.data_dir / "finsd.state").string() : std::string("(heap)");
    if (!opened) {
        const std::error_code error = opened.error().error;
        if (opened.error().setting_aside)
            return report_failure(3, file + ": cannot move it aside: " + error.message());
        const bool refused = Storage::is_refusal(error);
        std::string why = error.message();
        if (error == plc::state_file::make_error(plc::state_file::Error::other_profile))
            why += fmt::format(": the file is for profile '{}', this finsd runs '{}'",
                               state_file_profile(*s.data_dir), profile.name);
        return report_failure(3, file + ": " + why +
                                     (refused ? "; finsd never replaces it by itself: start "
                                                "with --reset-state to move it aside and "
                                                "begin with empty retained memory"
                                              : ""));
    }
    // Warnings about the operator's data go to stderr with the refusals, whatever the log
    // level (stdout's first line stays "listening <port>" at warn).
    if (opened->moved_aside)
        std::fprintf(stderr,
                     "finsd: warning: %s: %s; --reset-state moved it to %s: retained memory "
                     "starts empty\n",
                     file.c_str(), opened->refusal.message().c_str(),
                     opened->moved_aside->string().c_str());
    plc = std::move(opened->plc);
    return -1;
}

}  // namespace

int open_single(asio::io_context& io, const Settings& s, Served& served) {
    plc::Profile profile = *plc::find_profile(s.profile);
    if (s.dip_write_protection) profile.dip_switch |= plc::dip_pin1;
    if (auto r = mount_serial_units(s.serial, profile); !r) return report_failure(2, r.error());

    if (const int rc = open_plc(s, profile, served.single_plc); rc >= 0) return rc;
    plc::Plc& plc = *served.single_plc;
    const bool restored = plc.storage().restored();
    if (s.data_dir && restored && !plc.storage().checksums_verified())
        std::fprintf(stderr,
                     "finsd: warning: %s was not stopped cleanly (SIGKILL, crash or power "
                     "loss; or it was just converted from an earlier format): its header and "
                     "section table are intact; its data has no valid checksums to check\n",
                     plc.storage().path().string().c_str());
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
