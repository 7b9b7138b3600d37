// finsd: a virtual Omron CPU Unit answering FINS over UDP and TCP (README: profiles and
// configuration).
//
//   finsd [--config FILE] [flags]   serve; flags override the file (config.hpp)
//   finsd ctl ...                   the control channel's client (ctl.hpp)
//
// Start-up: settings -> Storage (the data directory's state file, or the heap) -> Plc
// -> seal the storage -> [memory] initial values -> protections, mode, [inject] ->
// Server -> control channel -> "listening <port>" on stdout.
//
// Exit codes: 0 clean shutdown (SIGINT/SIGTERM: the state file is flushed first),
// 2 usage or configuration error, 3 start-up failure (cannot bind, state file damaged,
// foreign or in use, control socket).
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include "cli/finsd/config.hpp"
#include "cli/finsd/ctl.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "plc/storage.hpp"
#include "server/control.hpp"
#include "server/server.hpp"

namespace {

using fins::cli::finsd::Overrides;
using fins::cli::finsd::Settings;

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
    std::string config;
    Overrides o;
    std::string profile, mode, data_dir, control, log_level, bind, protection;
    std::uint16_t port = 0;
    unsigned node = 0, network = 0;
    std::size_t max_connections = 0;
    bool udp = true, tcp = true, um_read = false, dip_write = false, list = false;
    app.add_option("--config", config, "TOML configuration file (keys: see README)");
    auto* o_profile = app.add_option("--profile", profile, "PLC profile (--list-profiles)");
    app.add_flag("--list-profiles", list, "Print the known profiles and exit");
    auto* o_mode =
        app.add_option("--mode", mode, "Operating mode at start-up: program, monitor, run");
    auto* o_data =
        app.add_option("--data-dir", data_dir, "Keep retained memory in DIR/finsd.state");
    auto* o_control = app.add_option("--control", control, "Control channel socket path");
    auto* o_bind =
        app.add_option("--bind", bind, "Address to listen on (IPv4 or IPv6; default 127.0.0.1)");
    auto* o_port =
        app.add_option("--port", port, "UDP and TCP port (0 = any free port; default 9600)");
    auto* o_node =
        app.add_option("--node", node,
                       "FINS node address 1-254 (default: last octet of --bind, 1 on loopback)")
            ->check(CLI::Range(1, 254));
    auto* o_network =
        app.add_option("--network", network, "FINS network address 0-127 (0 = local network)")
            ->check(CLI::Range(0, 127));
    auto* o_max = app.add_option("--max-connections", max_connections,
                                 "Maximum FINS/TCP connections (W596: 16)")
                      ->check(CLI::Range(1, 254));
    auto* o_udp = app.add_flag("--udp,!--no-udp", udp, "Serve FINS/UDP (default on)");
    auto* o_tcp = app.add_flag("--tcp,!--no-tcp", tcp, "Serve FINS/TCP (default on)");
    auto* o_log = app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
                      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
    auto* o_protection =
        app.add_option("--network-write-protection", protection,
                       "off, all, listed or all-except-listed (W342 5-1-2 note 5)");
    app.add_option("--protect-node", o.protect_nodes,
                   "A listed node, network.node (repeatable; node * = any)");
    auto* o_um = app.add_flag("--um-read-protection", um_read, "UM read protection set");
    auto* o_dip = app.add_flag("--dip-write-protection", dip_write,
                               "DIP switch pin 1 ON (UM write-protected)");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int rc = app.exit(e);
        return rc == 0 ? 0 : 2;
    }
    if (list) {
        list_profiles();
        return 0;
    }
    if (!config.empty())
        if (auto r = load_config_file(config, settings); !r) return fail(2, r.error());
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
    take(o_udp, udp, o.udp);
    take(o_tcp, tcp, o.tcp);
    take(o_protection, protection, o.network_write_protection);
    if (o_um->count() > 0) o.um_read_protection = true;
    if (o_dip->count() > 0) o.dip_write_protection = true;
    if (auto r = apply_overrides(o, settings); !r) return fail(2, r.error());
    if (auto r = validate(settings); !r) return fail(2, r.error());
    return -1;
}

int serve(const Settings& s) {
    spdlog::set_level(spdlog::level::from_str(s.log_level));
    fins::plc::Profile profile = *fins::plc::find_profile(s.profile);
    if (s.dip_write_protection) profile.dip_switch |= fins::plc::dip_pin1;

    std::unique_ptr<fins::plc::Storage> storage;
    if (s.data_dir) {
        auto opened = fins::plc::Storage::open(*s.data_dir, profile.name);
        if (!opened)
            return fail(3,
                        "data directory " + s.data_dir->string() + ": " + opened.error().message());
        storage = std::move(*opened);
    }
    fins::plc::Plc plc{profile, std::move(storage)};
    if (auto sealed = plc.storage().seal(); !sealed)
        return fail(
            3, "state file " + plc.storage().path().string() + ": " + sealed.error().message());
    const bool restored = plc.storage().restored();
    if (s.data_dir)
        spdlog::info("finsd: {} state file {}", restored ? "restored" : "new",
                     plc.storage().path().string());

    if (auto r = check_initial_memory(s.memory, plc.memory()); !r) return fail(2, r.error());
    const auto written = apply_initial_memory(s.memory, plc.memory(), restored);
    if (!s.memory.empty()) spdlog::info("finsd: {} [memory] entries written", written);
    plc.change_mode(s.mode, std::chrono::system_clock::now());
    plc.set_network_write_protection_setting(s.network_write_protection);
    plc.set_um_read_protection(s.um_read_protection);
    plc.set_um_password(s.um_password);
    plc.set_dip_write_protection(s.dip_write_protection);
    fins::plc::apply(s.inject, plc, std::chrono::system_clock::now());
    // File memory (22 xx): <data_dir>/card and <data_dir>/em; else a temp dir removed at exit.
    if (s.card_kbytes) {
        if (*s.card_kbytes == 0)
            plc.files().remove_card();
        else
            plc.files().insert_card(*s.card_kbytes);
    }
    if (s.em_file_bank) plc.files().set_em_file_bank(*s.em_file_bank);
    if (s.data_dir)
        if (auto r = plc.files().attach(*s.data_dir); !r)
            return fail(3, "file memory in " + s.data_dir->string() + ": " + r.error().message());

    fins::server::ServerOptions options;
    options.bind_address = s.bind;
    options.port = s.port;
    options.udp = s.udp;
    options.tcp = s.tcp;
    options.node = s.node;
    options.network = s.network;
    options.max_tcp_connections = s.max_connections;
    asio::io_context io{1};
    auto server = fins::server::Server::start(io, plc, options);
    if (!server)
        return fail(3, "cannot listen on " + s.bind + " port " + std::to_string(s.port) + ": " +
                           server.error().message());
    std::unique_ptr<fins::server::ControlServer> control;
    if (s.control_socket) {
        auto started = fins::server::ControlServer::start(io, plc, *s.control_socket);
        if (!started)
            return fail(3, "control channel " + s.control_socket->string() + ": " +
                               started.error().message());
        control = std::move(*started);
    }
    const auto self = (*server)->address();
    const unsigned port =
        (*server)->tcp_port() != 0 ? (*server)->tcp_port() : (*server)->udp_port();
    spdlog::info("finsd: {} ({}) on {} port {} (UDP {}, TCP {}), FINS address {}.{}.{}",
                 plc.profile().model, plc.profile().name, s.bind, port, s.udp ? "on" : "off",
                 s.tcp ? "on" : "off", self.network, self.node, self.unit);
    // A line on stdout that scripts and tests can wait for: "listening <port>".
    std::printf("listening %u\n", port);
    std::fflush(stdout);

    asio::signal_set signals{io, SIGINT, SIGTERM};
    signals.async_wait([&](std::error_code, int signal) {
        spdlog::info("finsd: signal {}, shutting down", signal);
        (*server)->stop();
        if (control) control->stop();
        plc.storage().flush();
        io.stop();
    });
    io.run();
    plc.storage().flush();
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 1 && std::string_view(argv[1]) == "ctl")
        return fins::cli::run_ctl(argc - 1, argv + 1);
    Settings settings;
    if (const int rc = configure(argc, argv, settings); rc >= 0) return rc;
    try {
        return serve(settings);
    } catch (const std::exception& e) {
        return fail(3, e.what());
    }
}
