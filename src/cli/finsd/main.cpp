// finsd: a virtual Omron CPU Unit answering FINS over UDP and TCP (docs/finsd.md:
// profiles and configuration).
//
//   finsd [--config FILE] [flags]   serve; flags override the file (config.hpp)
//   finsd ctl ...                   the control channel's client (ctl.hpp)
//
// Start-up: settings -> Storage (the data directory's state file, or the heap) -> Plc
// -> seal the storage -> [memory] initial values -> protections, mode, [inject] ->
// Server -> control channel -> "listening <port>" on stdout.
//
// Exit codes: 0 clean shutdown (SIGINT/SIGTERM: the state file is closed cleanly, with
// checksums), 2 usage or configuration error, 3 start-up failure (cannot bind, state
// file refused, in use or without room on disk, control socket), 4 the state file shrank
// while finsd ran (truncated from outside: plc/storage/storage_guard.hpp).
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include "finsd/config.hpp"
#include "finsd/config_plant.hpp"
#include "finsd/control_setup.hpp"
#include "finsd/ctl.hpp"
#include "finsd/process_os.hpp"
#include "finsd/scenario_setup.hpp"
#include "finsd/serial_gateway_setup.hpp"
#include "finsd/serial_ports.hpp"
#include "finsd/web_setup.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"
#include "plc/storage/storage_format.hpp"
#include "plc/storage/storage_guard.hpp"
#include "scenario/scenario.hpp"
#include "server/control/control.hpp"
#include "server/instructions/instruction_schedule.hpp"
#include "server/serial/serial_ports.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace {

using fins::finsd::Overrides;
using fins::finsd::Settings;

template <class T>
void take(CLI::Option* option, const T& value, std::optional<T>& out) {
    if (option->count() > 0) out = value;
}

int fail(int code, const std::string& message) {
    std::fprintf(stderr, "finsd: %s\n", message.c_str());
    return code;
}

// The profile a foreign state file was written for, to name it in the refusal: the
// header holds the profile name NUL-terminated (plc/storage/storage.cpp), so look for each known
// name there rather than depend on the header's offsets.
std::string state_file_profile(const std::filesystem::path& dir) {
    std::ifstream f(dir / "finsd.state", std::ios::binary);
    std::string head(4096, '\0');
    f.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(f.gcount()));
    for (const auto& p : fins::plc::profiles())
        if (head.find(std::string(1, '\0') + p.name + std::string(1, '\0')) != std::string::npos)
            return p.name;
    return "unknown";
}

void list_profiles() {
    std::printf("%-9s %-15s %5s %8s %s\n", "name", "model", "EM", "UM (K)", "notes");
    for (const auto& p : fins::plc::profiles())
        std::printf("%-9s %-15s %5u %8u %s%s%s\n", p.name.c_str(), p.model.c_str(),
                    static_cast<unsigned>(p.em_banks), static_cast<unsigned>(p.program_kwords),
                    p.cv_mode_codes ? "CV codes" : "no CV codes",
                    p.loop_control ? ", Loop Control Board" : "",
                    p.nx_fixed_values ? ", W596 FINS subset" : "");
}

// Parses the command line and the file into `settings`; returns an exit code, or -1
// to go on.
int configure(int argc, char** argv, Settings& settings) {
    CLI::App app{"finsd: a virtual Omron CPU Unit speaking FINS/UDP and FINS/TCP"};
    app.set_version_flag("--version", std::string("finsd ") + FINSKIT_VERSION);
    app.footer(
        "finsd ctl [--socket PATH] VERB ...: change a running finsd through its control channel\n"
        "(--control PATH, else $FINSD_SOCKET, else $XDG_RUNTIME_DIR/finsd.sock, else\n"
        "/run/finsd/finsd.sock for root or /tmp/finsd-UID/finsd.sock, the directory created);\n"
        "`finsd ctl --help` lists the verbs.\n"
        "Logs go to stderr; stdout carries only \"listening <port>\" once serving.\n"
        "Exit codes: 0 clean shutdown, 2 usage or configuration error, 3 start-up failure,\n"
        "4 the state file shrank (was truncated) while finsd ran.");
    std::string config;
    Overrides o;
    std::string profile, mode, data_dir, control, log_level, bind, protection;
    std::uint16_t port = 0;
    unsigned node = 0, network = 0;
    std::size_t max_connections = 0;
    std::string durability;
    bool udp = true, tcp = true, um_read = false, dip_write = false, list = false;
    app.add_option("--config", config, "TOML configuration file (every key: docs/finsd.md)");
    auto* o_profile = app.add_option("--profile", profile, "PLC profile (--list-profiles)");
    app.add_flag("--list-profiles", list, "Print the known profiles and exit");
    auto* o_mode =
        app.add_option("--mode", mode, "Operating mode at start-up: program, monitor, run");
    auto* o_data = app.add_option(
        "--data-dir", data_dir,
        "Keep retained memory in DIR/finsd.state (DIR and its parents are created if missing)");
    auto* o_control = app.add_option(
        "--control", control,
        "Control channel socket path (default $FINSD_SOCKET, $XDG_RUNTIME_DIR/finsd.sock, "
        "/run/finsd/finsd.sock (root) or /tmp/finsd-UID/finsd.sock)");
    auto* o_bind =
        app.add_option("--bind", bind, "Address to listen on (IPv4 or IPv6; default 127.0.0.1)");
    auto* o_port =
        app.add_option("--port", port,
                       "UDP and TCP port (0 = any free port; default 9600); in a plant, of each "
                       "[[plc.ethernet]] unit without a port of its own");
    auto* o_node =
        app.add_option("--node", node,
                       "FINS node address 1-254 (default: last octet of --bind; 1 for 0.0.0.0, ::)")
            ->check(CLI::Range(1, 254));
    auto* o_network =
        app.add_option("--network", network, "FINS network address 0-127 (0 = local network)")
            ->check(CLI::Range(0, 127));
    auto* o_max = app.add_option("--max-connections", max_connections,
                                 "Maximum FINS/TCP connections (W596: 16)")
                      ->check(CLI::Range(1, 254));
    unsigned tcp_handshake = 0, tcp_frame = 0, tcp_idle = 0, tcp_keepalive = 0;
    std::size_t tcp_pending = 0;
    auto* o_tcp_handshake =
        app.add_option("--tcp-handshake-timeout", tcp_handshake,
                       "Seconds from accept to the FINS/TCP handshake (default 10)")
            ->check(CLI::Range(1, 3600));
    auto* o_tcp_frame = app.add_option("--tcp-frame-timeout", tcp_frame,
                                       "Seconds for a begun FINS/TCP packet to end (default 10)")
                            ->check(CLI::Range(1, 3600));
    auto* o_tcp_idle =
        app.add_option("--tcp-idle-timeout", tcp_idle,
                       "Seconds a FINS/TCP connection may stay silent (0 = no limit; default 300)")
            ->check(CLI::Range(0, 86400));
    auto* o_tcp_keepalive =
        app.add_option("--tcp-keepalive", tcp_keepalive,
                       "TCP keep-alive: seconds of silence before the first probe (0 = off; "
                       "default 60)")
            ->check(CLI::Range(0, 7200));
    auto* o_tcp_pending =
        app.add_option("--tcp-max-pending", tcp_pending,
                       "Connections without a finished handshake (default 16; more close the "
                       "oldest)")
            ->check(CLI::Range(1, 1024));
    auto* o_udp = app.add_flag("--udp,!--no-udp", udp, "Serve FINS/UDP (default on)");
    auto* o_tcp = app.add_flag("--tcp,!--no-tcp", tcp, "Serve FINS/TCP (default on)");
    auto* o_log = app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
                      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
    auto* o_protection =
        app.add_option("--network-write-protection", protection,
                       "off, all, listed or all-except-listed (W342 5-1-2 note 5)");
    auto* o_nodes = app.add_option("--protect-node", o.protect_nodes,
                                   "A listed node, network.node (repeatable; node * = any)");
    auto* o_um = app.add_flag("--um-read-protection", um_read, "UM read protection set");
    auto* o_dip = app.add_flag("--dip-write-protection", dip_write,
                               "DIP switch pin 1 ON (UM write-protected)");
    auto* o_durability =
        app.add_option("--durability", durability,
                       "What an acknowledged write survives: process (SIGKILL) or power "
                       "(fdatasync before each write's answer)")
            ->check(CLI::IsMember({"process", "power"}));
    app.add_option("--serial", o.serial,
                   "Serial port NAME=DEVICE[,baud=9600,parity=even,data=7,stop=2,unit=0,mode=..."
                   ",timeout=1]; NAME cpu, scuN.P or board.P (repeatable; docs/serial.md)");
    fins::finsd::HttpFlags http;
    fins::finsd::add_http_flags(app, http);

    std::string scenario_file;
    auto* o_scenario = app.add_option(
        "--scenario", scenario_file,
        "A file with a [scenario] table: signals, links and events that make memory move "
        "(docs/scenarios.md); replaces the configuration's [scenario]");
    std::string scenario_time;
    auto* o_time = app.add_option("--scenario-time", scenario_time,
                                  "real or virtual: replaces every scenario's `time`")
                       ->check(CLI::IsMember({"real", "virtual"}));
    app.add_flag("--reset-state", o.reset_state,
                 "Move a refused state file aside (never deleted) and start with a new one");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
        return fail(2, std::string(e.what()) + " (see finsd --help)");
    }
    if (list) {
        list_profiles();
        return 0;
    }
    if (!config.empty())
        if (auto r = load_config_file(config, settings); !r) return fail(2, r.error());
    if (o_scenario->count() > 0) {
        if (!settings.plant.cpus.empty())
            return fail(2,
                        "--scenario is for a single node: give each [[plc]] its own "
                        "[plc.scenario] (docs/scenarios.md)");
        auto loaded = fins::finsd::load_scenario_file(scenario_file);
        if (!loaded) return fail(2, loaded.error());
        settings.scenario = std::move(*loaded);
    }
    if (o_time->count() > 0)
        if (auto r = fins::finsd::override_scenario_time(settings, scenario_time); !r)
            return fail(2, r.error());
    take(o_profile, profile, o.profile);
    take(o_mode, mode, o.mode);
    take(o_data, data_dir, o.data_dir);
    take(o_control, control, o.control_socket);
    take(o_log, log_level, o.log_level);
    take(o_bind, bind, o.bind);
    take(o_port, port, o.port);
    take(o_node, node, o.node);
    take(o_network, network, o.network);
    take(o_max, max_connections, o.max_connections);
    take(o_tcp_handshake, tcp_handshake, o.tcp_handshake_timeout);
    take(o_tcp_frame, tcp_frame, o.tcp_frame_timeout);
    take(o_tcp_idle, tcp_idle, o.tcp_idle_timeout);
    take(o_tcp_keepalive, tcp_keepalive, o.tcp_keepalive);
    take(o_tcp_pending, tcp_pending, o.tcp_max_pending);
    take(o_udp, udp, o.udp);
    take(o_tcp, tcp, o.tcp);
    take(o_protection, protection, o.network_write_protection);
    if (o_um->count() > 0) o.um_read_protection = true;
    if (o_dip->count() > 0) o.dip_write_protection = true;
    take(o_durability, durability, o.durability);
    if (auto r = apply_overrides(o, settings); !r) return fail(2, r.error());
    if (auto r = validate(settings); !r) return fail(2, r.error());
    fins::finsd::apply_http_flags(http, settings.http);
    if (auto r = check_http(settings.http); !r) return fail(2, r.error());
    // A node list protects nothing unless the mode reads it: refuse the flag rather than
    // let someone believe those nodes are refused (or, under "all", the only ones).
    const auto write_mode = settings.network_write_protection.mode;
    using fins::plc::NetworkWriteProtection;
    if (o_nodes->count() > 0 &&
        (write_mode == NetworkWriteProtection::off || write_mode == NetworkWriteProtection::all))
        return fail(2, fmt::format("--protect-node has no effect with network write protection "
                                   "'{}': add --network-write-protection listed (refuse those "
                                   "nodes) or all-except-listed (accept only those)",
                                   write_mode == NetworkWriteProtection::off ? "off" : "all"));
    if (!settings.network_write_protection.nodes.empty() &&
        write_mode == NetworkWriteProtection::off)
        spdlog::warn(
            "finsd: protection.nodes is set but protection.network_write is \"off\": "
            "no node is refused");
    return -1;
}

// The PLC on its state file (or the heap) into `plc` (plc::open_plc); -1, or the exit
// code. A state file refused for its content stops finsd unless --reset-state.
int open_plc(const Settings& s, const fins::plc::Profile& profile,
             std::unique_ptr<fins::plc::Plc>& plc) {
    using fins::plc::Storage;
    auto opened = fins::plc::open_plc(profile, s.data_dir, {s.durability}, s.reset_state);
    const std::string file =
        s.data_dir ? (*s.data_dir / "finsd.state").string() : std::string("(heap)");
    if (!opened) {
        const std::error_code error = opened.error().error;
        if (opened.error().setting_aside)
            return fail(3, file + ": cannot move it aside: " + error.message());
        const bool refused = Storage::is_refusal(error);
        std::string why = error.message();
        if (error == fins::plc::state_file::make_error(fins::plc::state_file::Error::other_profile))
            why += fmt::format(": the file is for profile '{}', this finsd runs '{}'",
                               state_file_profile(*s.data_dir), profile.name);
        return fail(3, file + ": " + why +
                           (refused ? "; finsd never replaces it by itself: start with "
                                      "--reset-state to move it aside and begin with "
                                      "empty retained memory"
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

int serve(const Settings& s) {
    spdlog::set_level(spdlog::level::from_str(s.log_level));
    fins::finsd::ignore_file_size_signal();
    fins::plc::Profile profile = *fins::plc::find_profile(s.profile);
    if (s.dip_write_protection) profile.dip_switch |= fins::plc::dip_pin1;
    if (auto r = fins::finsd::mount_serial_units(s.serial, profile); !r) return fail(2, r.error());

    std::unique_ptr<fins::plc::Plc> plc_owner;
    if (const int rc = open_plc(s, profile, plc_owner); rc >= 0) return rc;
    fins::plc::Plc& plc = *plc_owner;
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

    if (auto r = check_initial_memory(s.memory, plc.memory()); !r) return fail(2, r.error());
    if (auto r = check_schedule(s, plc.memory()); !r) return fail(2, r.error());
    const auto written = apply_initial_memory(s.memory, plc.memory(), restored);
    if (!s.memory.empty()) spdlog::info("finsd: {} [memory] entries written", written);
    plc.change_mode(s.mode, std::chrono::system_clock::now());
    fins::finsd::apply_cpu_options(s, plc);
    // [scenario], --scenario: compiled against this CPU Unit; every error is a start error.
    std::unique_ptr<fins::scenario::Scenario> scenario;
    if (s.scenario) {
        auto compiled = fins::finsd::compile_scenario(*s.scenario, plc);
        if (!compiled) return fail(2, compiled.error());
        scenario = std::move(*compiled);
    }
    // File memory (22 xx): <data_dir>/card and <data_dir>/em; else a temp dir removed at exit.
    if (const auto refused = fins::server::set_up_file_memory(plc, s, s.data_dir, ""))
        return fail(3, refused->message);

    // The same translation as each unit of a plant gets (server/routing/plant.hpp).
    auto options =
        fins::server::options_for(fins::finsd::single_unit(s), fins::finsd::tcp_limits(s));
    options.remotes = s.remotes;
    asio::io_context io{1};
    auto server = fins::server::Server::start(io, plc, options);
    if (!server)
        return fail(3, "cannot listen on " + s.bind + " port " + std::to_string(s.port) + ": " +
                           server.error().message());
    // [[schedule]]: this node's own Send/Rcv/SendCmd at fixed periods.
    std::vector<fins::server::ScheduledInstruction> scheduled;
    for (const auto& e : s.schedule)
        scheduled.push_back(e.scheduled);
    fins::server::InstructionSchedule schedule(io.get_executor(), (*server)->instructions(),
                                               std::move(scheduled));
    schedule.start();
    // Serial Gateway ports (scuN.P / board.P in mode gateway): serial_gateway_setup.hpp.
    fins::server::SerialPorts gateway_ports;
    fins::finsd::open_gateway_ports(io, s.serial, gateway_ports);
    (*server)->attach_serial_ports(&gateway_ports);
    // The scenario's ticks are computed on finsd's scenario thread, handed over on this
    // io_context; its unit faults reach the dispatcher.
    std::unique_ptr<fins::server::ScenarioWorker> scenario_worker;
    auto runner = fins::finsd::run_scenario(io, s.scenario, std::move(scenario), plc, std::nullopt,
                                            scenario_worker);
    if (runner) (*server)->dispatcher().attach_faults(runner.get());
    // --control, FINSD_SOCKET or the default path (control_setup.hpp).
    fins::server::ControlTarget target;
    target.scenario = runner.get();
    target.plc = &plc;
    target.addresses = {{(*server)->address().network, (*server)->address().node}};
    target.instructions = &(*server)->instructions();
    target.schedule = &schedule;
    // --http (docs/web.md): the same CPU Unit, on this io_context.
    auto web = fins::finsd::start_web(io, s.http, {target}, {server->get()});
    if (web.exit_code >= 0) return fail(web.exit_code, web.error);
    auto control_start = fins::finsd::start_control(io, {std::move(target)}, s.control_socket);
    if (control_start.exit_code >= 0) return fail(control_start.exit_code, control_start.error);
    auto& control = control_start.server;
    fins::finsd::SerialPorts serial;
    if (auto r = start_serial_ports(io, (*server)->dispatcher(), s.serial, serial); !r)
        return fail(2, r.error());
    // Before "listening": a SIGTERM right after that line still stops finsd cleanly.
    asio::signal_set signals{io, SIGINT, SIGTERM};
    const auto self = (*server)->address();
    const unsigned port =
        (*server)->tcp_port() != 0 ? (*server)->tcp_port() : (*server)->udp_port();
    spdlog::info("finsd: {} ({}) on {} port {} (UDP {}, TCP {}), FINS address {}.{}.{}",
                 plc.profile().model, plc.profile().name, s.bind, port, s.udp ? "on" : "off",
                 s.tcp ? "on" : "off", self.network, self.node, self.unit);
    // A line on stdout that scripts and tests can wait for: "listening <port>".
    std::printf("listening %u\n", port);
    std::fflush(stdout);

    const auto shut_down = [&] {
        schedule.stop();
        if (runner) runner->stop();
        (*server)->stop();
        gateway_ports.close_all();
        if (control) control->stop();
        if (web.server) web.server->stop();
        serial.stop();
        plc.storage().flush();
        io.stop();
    };
    signals.async_wait([&](std::error_code, int signal) {
        spdlog::info("finsd: signal {}, shutting down", signal);
        shut_down();
    });
    // A state file truncated from outside is caught by the SIGBUS guard at the next
    // access; this look once a second also catches it while nothing touches the file.
    asio::steady_timer file_check{io};
    std::function<void()> check_file = [&] {
        file_check.expires_after(std::chrono::seconds(1));
        file_check.async_wait([&](std::error_code ec) {
            if (ec) return;
            if (!plc.storage().intact()) return shut_down();
            check_file();
        });
    };
    if (s.data_dir) check_file();
    io.run();
    if (!plc.storage().intact()) {
        std::fputs(fins::plc::state_file_lost_message(plc.storage().path().string()).c_str(),
                   stderr);
        return fins::plc::state_file_lost_exit_code;
    }
    plc.storage().close();  // sections on disk, then their checksums and "stopped cleanly"
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    // Logs on stderr: stdout carries only "listening <port>" (and `finsd ctl` answers).
    spdlog::set_default_logger(std::make_shared<spdlog::logger>(
        "", std::make_shared<spdlog::sinks::stderr_color_sink_mt>()));
    if (argc > 1 && std::string_view(argv[1]) == "ctl")
        return fins::finsd::run_ctl(argc - 1, argv + 1);
    Settings settings;
    if (const int rc = configure(argc, argv, settings); rc >= 0) return rc;
    try {
        if (!settings.plant.cpus.empty()) return fins::finsd::serve_plant(settings);
        return serve(settings);
    } catch (const std::exception& e) {
        return fail(3, e.what());
    }
}
