// finsd's one composition root (contract in serve.hpp).
#include <chrono>
#include <csignal>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include "finsd/control_setup.hpp"
#include "finsd/process_os.hpp"
#include "finsd/serve.hpp"
#include "finsd/serve_units.hpp"
#include "finsd/web_setup.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage_guard.hpp"
#include "server/control/control.hpp"

namespace fins::finsd {

namespace {

// The control channel's and the web front's view of each CPU Unit (`finsd ctl --plc
// NAME|NET.NODE`; the first without --plc). Network instructions leave through its first
// unit; its [[schedule]]'s counters are listed whichever units run them.
std::vector<server::ControlTarget> control_targets(const Served& served,
                                                   const CpuUnitExtras& extras) {
    std::vector<server::ControlTarget> targets(served.cpus.size());
    for (std::size_t i = 0; i < targets.size(); ++i) {
        const auto& cpu = served.cpus[i];
        auto& t = targets[i];
        t.plc = cpu.plc;
        t.name = cpu.name;
        t.instructions = &cpu.units.front()->instructions();
        if (i < extras.schedule_entries.size()) t.schedule = extras.schedule_entries[i];
        if (i < extras.scenarios.size()) t.scenario = extras.scenarios[i].get();
        for (const auto* unit : cpu.units)
            t.addresses.emplace_back(unit->address().network, unit->address().node);
    }
    return targets;
}

unsigned port_of(const server::Server& server) {
    return server.tcp_port() != 0 ? server.tcp_port() : server.udp_port();
}

// What serves where, at info: the single node's one line; a plant's summary and a line
// per unit (at debug above units_logged_at_info units).
void log_serving(const Settings& s, const Served& served) {
    if (!served.is_plant()) {
        const auto& plc = *served.cpus[0].plc;
        const auto& server = *served.cpus[0].units[0];
        const auto self = server.address();
        spdlog::info("finsd: {} ({}) on {} port {} (UDP {}, TCP {}), FINS address {}.{}.{}",
                     plc.profile().model, plc.profile().name, s.bind, port_of(server),
                     s.udp ? "on" : "off", s.tcp ? "on" : "off", self.network, self.node,
                     self.unit);
        return;
    }
    std::size_t units = 0;
    for (const auto& cpu : served.cpus)
        units += cpu.units.size();
    const auto unit_level =
        units <= units_logged_at_info ? spdlog::level::info : spdlog::level::debug;
    if (spdlog::should_log(unit_level))
        for (const auto& cpu : served.cpus)
            for (std::size_t k = 0; k < cpu.units.size(); ++k) {
                const auto self = cpu.units[k]->address();
                spdlog::log(unit_level,
                            "finsd: plc \"{}\" unit {} is FINS node {}.{} on {} port {}", cpu.name,
                            cpu.config->ports[k].unit_number, self.network, self.node,
                            cpu.config->ports[k].bind, port_of(*cpu.units[k]));
            }
    spdlog::info("finsd: plant of {} CPU Units, {} units{}", served.cpus.size(), units,
                 unit_level == spdlog::level::info ? "" : " (a line per unit at debug level)");
}

// True when some CPU Unit keeps a state file (only those can shrink).
bool keeps_state_files(const Served& served) {
    for (const auto& cpu : served.config.cpus)
        if (cpu.data_dir) return true;
    return false;
}

// The state files that shrank under finsd (storage_guard.hpp), each named on stderr in
// the guard's own line. True when there was one.
bool report_lost_state_files(const Served& served) {
    bool lost = false;
    for (const auto& cpu : served.cpus)
        if (!cpu.plc->storage().intact()) {
            std::fputs(plc::state_file_lost_message(cpu.plc->storage().path().string()).c_str(),
                       stderr);
            lost = true;
        }
    return lost;
}

bool all_intact(const Served& served) {
    for (const auto& cpu : served.cpus)
        if (!cpu.plc->storage().intact()) return false;
    return true;
}

}  // namespace

int serve(const Settings& s) {
    spdlog::set_level(spdlog::level::from_str(s.log_level));
    ignore_file_size_signal();
    asio::io_context io{1};
    // Declared in this order: the extras stop and go before the CPU Units they use.
    Served served;
    const int opened =
        s.plant.cpus.empty() ? open_single(io, s, served) : open_plant(io, s, served);
    if (opened >= 0) return opened;
    CpuUnitExtras extras;
    for (std::size_t i = 0; i < served.cpus.size(); ++i)
        if (const int rc = set_up_cpu(io, served, i, extras); rc >= 0) {
            extras.stop();
            return rc;
        }
    auto targets = control_targets(served, extras);
    // --http (docs/web.md): every CPU Unit, each with all its Ethernet units' servers.
    std::vector<UnitServers> units;
    for (const auto& cpu : served.cpus)
        units.emplace_back(cpu.units.begin(), cpu.units.end());
    auto web = start_web(io, s.http, targets, std::move(units), served.plant.get());
    if (web.exit_code >= 0) {
        extras.stop();
        return report_failure(web.exit_code, web.error);
    }
    // --control, FINSD_SOCKET or the default path (control_setup.hpp).
    auto control_start = start_control(io, std::move(targets), s.control_socket);
    if (control_start.exit_code >= 0) {
        extras.stop();
        return report_failure(control_start.exit_code, control_start.error);
    }
    auto& control = control_start.server;
    // Before "listening": a SIGTERM right after that line still stops finsd cleanly.
    asio::signal_set signals{io, SIGINT, SIGTERM};
    log_serving(s, served);
    // A line on stdout that scripts and tests can wait for: "listening <port>" (a plant's
    // first unit's).
    std::printf("listening %u\n", port_of(*served.cpus[0].units[0]));
    std::fflush(stdout);

    const auto shut_down = [&] {
        extras.stop();
        served.stop();
        if (control) control->stop();
        if (web.server) web.server->stop();
        io.stop();
    };
    signals.async_wait([&](std::error_code, int signal) {
        spdlog::info("finsd: signal {}, shutting down", signal);
        shut_down();
    });
    // A state file truncated from outside is caught by the SIGBUS guard at the next
    // access; this look once a second at every CPU Unit's file also catches it while
    // nothing touches the file.
    asio::steady_timer file_check{io};
    std::function<void()> check_files = [&] {
        file_check.expires_after(std::chrono::seconds(1));
        file_check.async_wait([&](std::error_code ec) {
            if (ec) return;
            if (!all_intact(served)) return shut_down();
            check_files();
        });
    };
    if (keeps_state_files(served)) check_files();
    io.run();
    // One exit rule: any state file lost is exit 4, and no seal over its lost data;
    // else every state file is closed cleanly (sections, then checksums).
    if (report_lost_state_files(served)) return plc::state_file_lost_exit_code;
    for (const auto& cpu : served.cpus)
        cpu.plc->storage().close();
    return 0;
}

}  // namespace fins::finsd
