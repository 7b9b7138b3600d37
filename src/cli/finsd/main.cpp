// finsd: a virtual Omron CPU Unit answering FINS over UDP and TCP (docs/finsd.md:
// profiles and configuration).
//
//   finsd [--config FILE] [flags]   serve; flags override the file (config.hpp)
//   finsd ctl ...                   the control channel's client (ctl.hpp)
//
// This file is the command line only: flags and the file become Settings (configure),
// then fins::finsd::serve (src/finsd/serve.hpp) starts the single node or the plant,
// serves it, and gives the exit code: 0 clean shutdown, 2 usage or configuration error,
// 3 start-up failure, 4 a state file shrank while finsd ran.
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "finsd/config.hpp"
#include "finsd/ctl.hpp"
#include "finsd/scenario_setup.hpp"
#include "finsd/serve.hpp"
#include "plc/profile.hpp"

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
    // Options are --name on Windows too, and an argument such as /path is a value there.
    app.allow_windows_style_options(false);
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
        return fins::finsd::serve(settings);
    } catch (const std::exception& e) {
        return fail(3, e.what());
    }
}
