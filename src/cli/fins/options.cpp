// The global options of `fins` (where the PLC is, how to reach it, --json), node
// addresses and the connection every verb opens with them.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "cli/fins/commands.hpp"
#include "fins/client.hpp"
#include "transport/serial_options.hpp"

namespace fins::cli {

namespace {

// One part of NET.NODE.UNIT: decimal, 0x-prefixed hex, or hex when it has a letter A-F
// (docs/cli.md and the manuals write unit addresses such as E1 in hex).
std::optional<unsigned> parse_node_part(std::string_view s) {
    int base = 10;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
        base = 16;
        s.remove_prefix(2);
    } else if (s.find_first_of("abcdefABCDEF") != std::string_view::npos) {
        base = 16;
    }
    unsigned v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
    if (s.empty() || ec != std::errc{} || end != s.data() + s.size() || v > 255)
        return std::nullopt;
    return v;
}

}  // namespace

std::optional<NodeAddress> parse_node_address(const std::string& s) {
    unsigned parts[3] = {0, 0, 0};
    const auto dots = static_cast<std::size_t>(std::count(s.begin(), s.end(), '.'));
    if (dots != 1 && dots != 2) return std::nullopt;
    std::string_view rest = s;
    for (std::size_t i = 0; i <= dots; ++i) {
        const auto dot = rest.find('.');
        const auto v = parse_node_part(rest.substr(0, dot));
        if (!v) return std::nullopt;
        parts[i] = *v;
        rest = dot == std::string_view::npos ? std::string_view{} : rest.substr(dot + 1);
    }
    if (parts[0] > 127) return std::nullopt;
    return NodeAddress{static_cast<std::uint8_t>(parts[0]), static_cast<std::uint8_t>(parts[1]),
                       static_cast<std::uint8_t>(parts[2])};
}

std::optional<std::string> check_node_options(const GlobalOptions& g) {
    if (!g.dest.empty() && !parse_node_address(g.dest))
        return fmt::format("--dest '{}' is not NET.NODE[.UNIT] (e.g. 0.10, 0.10.0, 0.10.E1)",
                           g.dest);
    if (!g.source.empty() && !parse_node_address(g.source))
        return fmt::format("--source '{}' is not NET.NODE[.UNIT] (e.g. 0.20)", g.source);
    return std::nullopt;
}

std::string endpoint(const GlobalOptions& g) {
    if (!g.serial.empty())
        return fmt::format("{} unit {}", g.serial.substr(0, g.serial.find(',')), g.unit);
    if (g.host.find(':') != std::string::npos) return fmt::format("[{}]:{}", g.host, g.port);
    return fmt::format("{}:{}", g.host, g.port);
}

std::unique_ptr<Client> open_client(const GlobalOptions& g, Output& out, int& exit_code) {
    out.set_target(g);
    ClientOptions o;
    o.host = g.host;
    o.port = g.port;
    o.protocol = g.tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
    if (!g.serial.empty()) {
        if (g.tcp) {
            exit_code = out.usage("--serial and --tcp exclude each other");
            return nullptr;
        }
        auto spec = transport::parse_serial_spec(g.serial, transport::SerialKeys::line);
        if (!spec) {
            exit_code = out.usage(fmt::format("--serial: {}", spec.error()));
            return nullptr;
        }
        o.protocol = ClientOptions::Protocol::serial;
        o.serial = spec->line;
        o.host_link_unit = static_cast<std::uint8_t>(g.unit);
    }
    o.timeout = std::chrono::milliseconds(static_cast<long>(g.timeout_seconds * 1000.0 + 0.5));
    o.retries = g.retries;
    if (const auto bad = check_node_options(g)) {
        exit_code = out.usage(*bad);
        return nullptr;
    }
    if (!g.dest.empty()) o.destination = *parse_node_address(g.dest);
    if (!g.source.empty()) o.source = *parse_node_address(g.source);
    auto client = Client::connect(o);
    if (!client) {
        // Only TCP connects; over UDP (and Host Link) nothing was sent yet.
        exit_code = out.failure(client.error(), g.tcp ? "cannot connect"
                                                : !g.serial.empty()
                                                    ? "cannot open the serial line"
                                                    : "cannot send over UDP (nothing was sent)");
        return nullptr;
    }
    out.set_local_node((*client)->source());
    return std::move(*client);
}

std::optional<std::string> apply_environment(GlobalOptions& g, int argc, char** argv) {
    // A flag on the command line wins: its variable is not even looked at.
    auto given = [&](std::string_view flag) {
        for (int i = 1; i < argc; ++i) {
            const std::string_view arg = argv[i];
            if (arg == flag || (arg.size() > flag.size() && arg.substr(0, flag.size()) == flag &&
                                arg[flag.size()] == '='))
                return true;
        }
        return false;
    };
    if (const char* host = std::getenv("FINS_HOST"); host != nullptr && !given("--host")) {
        if (*host == '\0') return "FINS_HOST is set but empty (unset it or name the PLC's host)";
        g.host = host;
    }
    if (const char* port = std::getenv("FINS_PORT"); port != nullptr && !given("--port")) {
        const std::string_view text = port;
        unsigned v = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        if (text.empty() || ec != std::errc{} || end != text.data() + text.size() || v == 0 ||
            v > 65535)
            return fmt::format("FINS_PORT '{}' is not a port number 1-65535", text);
        g.port = static_cast<std::uint16_t>(v);
    }
    return std::nullopt;
}

void add_global_options(CLI::App& app, GlobalOptions& g) {
    app.add_option("--host", g.host, "PLC host name or IP address (environment: FINS_HOST)")
        ->capture_default_str();
    app.add_option("--port", g.port, "FINS port (environment: FINS_PORT)")->capture_default_str();
    app.add_flag("--tcp", g.tcp, "Use FINS/TCP instead of FINS/UDP");
    app.add_option("--serial", g.serial,
                   "FINS over Host Link on DEVICE[,baud=9600,parity=even,data=7,stop=2]");
    app.add_option("--unit", g.unit, "Host Link unit number of the PLC (with --serial)")
        ->capture_default_str()
        ->check(CLI::Range(0, 31));
    app.add_option("--timeout", g.timeout_seconds, "Seconds to wait for each attempt")
        ->capture_default_str()
        ->check(CLI::Range(0.001, 3600.0));
    app.add_option("--retries", g.retries, "Retransmissions after a timeout (0-15, W596)")
        ->capture_default_str()
        ->check(CLI::Range(0, 15));
    app.add_option("--dest", g.dest,
                   "Destination NET.NODE[.UNIT], unit in hex allowed (0.10.E1; 0.10 is unit 0); "
                   "default: derived (`fins probe` finds the PLC's node)");
    app.add_option("--source", g.source,
                   "Source NET.NODE[.UNIT] (default: derived; `fins probe` shows it)");
    app.add_flag("--json", g.json, "Print JSON");
}

void describe_global_options(CLI::App& app) {
    std::string text = "Global options (before or after the verb):\n";
    for (const CLI::Option* o : app.get_options()) {
        const std::string name = o->get_name(false, true);
        if (name.empty() || name == "-h,--help" || name == "--version") continue;
        std::string left = name;
        if (o->get_type_size() != 0) {
            const std::string type = o->get_type_name();
            left += " " + type.substr(0, type.find(':'));  // "FLOAT:FLOAT in [...]" -> FLOAT
        }
        std::string desc = o->get_description();
        if (!o->get_default_str().empty()) desc += " [" + o->get_default_str() + "]";
        text += fmt::format("  {:<22}{}\n", left, desc);
    }
    text += "Exit codes: 0 ok, 2 usage, 3 transport, 4 the PLC answered an end code.";
    for (CLI::App* sub : app.get_subcommands({}))
        sub->footer(text);
    app.footer(
        "`fins VERB --help` describes a verb; `fins probe` shows the PLC's node.\n"
        "Exit codes: 0 ok, 2 usage, 3 transport, 4 the PLC answered an end code.");
}

}  // namespace fins::cli
