#include "finsd/config_serial.hpp"

#include <fmt/format.h>

#include "codec/hex.hpp"
#include "transport/serial_options.hpp"

namespace fins::finsd {
namespace {

using Fail = tl::unexpected<std::string>;

bool port_number(std::string_view s, unsigned& port) {
    if (s != "1" && s != "2") return false;
    port = static_cast<unsigned>(s[0] - '0');
    return true;
}

// Unit, mode and timeout from the spec onto the port, with the port-level checks.
tl::expected<void, std::string> take_spec(SerialPortConfig& port,
                                          const transport::SerialSpec& spec) {
    port.line = spec.line;
    if (spec.unit) port.host_link_unit = *spec.unit;
    if (spec.mode) {
        if (*spec.mode != "hostlink" && *spec.mode != "gateway")
            return Fail(fmt::format("mode '{}': not hostlink or gateway", *spec.mode));
        port.mode = *spec.mode;
    }
    if (spec.network) port.network = *spec.network;
    if (spec.timeout_seconds) {
        if (*spec.timeout_seconds < min_serial_timeout ||
            *spec.timeout_seconds > max_serial_timeout)
            return Fail(
                fmt::format("timeout '{}': seconds, 0.1-25.5 (W336)", *spec.timeout_seconds));
        port.timeout_seconds = *spec.timeout_seconds;
    }
    return {};
}

std::string at(const toml::source_region& where, std::string_view source) {
    return fmt::format("{}:{}:{}", source, where.begin.line, where.begin.column);
}

}  // namespace

tl::expected<SerialPortConfig, std::string> parse_serial_name(std::string_view name) {
    SerialPortConfig p;
    p.name = std::string(name);
    p.mode = "gateway";
    if (name == "cpu") {
        p.kind = SerialPortConfig::Kind::cpu;
        p.mode = "hostlink";
        return p;
    }
    const auto bad = [&] {
        return Fail(
            fmt::format("port name '{}': not cpu, scuN.P (N 0-F, P 1 or 2) or board.P", name));
    };
    const auto dot = name.find('.');
    if (dot == std::string_view::npos) return bad();
    const auto head = name.substr(0, dot);
    if (!port_number(name.substr(dot + 1), p.port)) return bad();
    if (head == "board") {
        p.kind = SerialPortConfig::Kind::board;
        return p;
    }
    if (head.size() < 4 || head.substr(0, 3) != "scu") return bad();
    const auto digits = head.substr(3);
    const auto n = hex::parse_number(digits, 16, hex::Prefix::none);
    if (!n) return bad();
    if (*n > 15) return Fail(fmt::format("port name '{}': unit number {} is over F", name, digits));
    p.kind = SerialPortConfig::Kind::scu;
    p.unit_number = static_cast<unsigned>(*n);
    return p;
}

tl::expected<SerialPortConfig, std::string> parse_serial_option(std::string_view text) {
    const auto fail = [&](const std::string& why) {
        return Fail(fmt::format("--serial {}: {}", text, why));
    };
    const auto eq = text.find('=');
    if (eq == std::string_view::npos)
        return fail(fmt::format("not NAME=DEVICE[,baud=...] (e.g. cpu={},unit=0)",
                                transport::example_serial_device));
    auto port = parse_serial_name(text.substr(0, eq));
    if (!port) return fail(port.error());
    auto spec = transport::parse_serial_spec(text.substr(eq + 1), transport::SerialKeys::port);
    if (!spec) return fail(spec.error());
    if (auto r = take_spec(*port, *spec); !r) return fail(r.error());
    port->where = "--serial";
    return port;
}

tl::expected<void, std::string> load_serial_table(const toml::node& node, std::string_view source,
                                                  std::vector<SerialPortConfig>& ports) {
    const auto* table = node.as_table();
    if (table == nullptr) return Fail(fmt::format("{}: serial: must be a table", source));
    for (auto&& [key, value] : *table) {
        const std::string path = fmt::format("serial.{}", key.str());
        const std::string where = at(key.source(), source);
        const auto fail = [&](const std::string& why) {
            return Fail(fmt::format("{}: {}: {}", where, path, why));
        };
        auto port = parse_serial_name(key.str());
        if (!port) return fail(port.error());
        transport::SerialSpec spec;
        if (const auto* s = value.as_string()) {
            auto parsed = transport::parse_serial_spec(s->get(), transport::SerialKeys::port);
            if (!parsed) return fail(parsed.error());
            spec = *parsed;
        } else if (const auto* t = value.as_table()) {
            for (auto&& [k, v] : *t) {
                const std::string name(k.str());
                std::string text;
                if (const auto* str = v.as_string())
                    text = str->get();
                else if (const auto* i = v.as_integer())
                    text = std::to_string(i->get());
                else if (const auto* d = v.as_floating_point())
                    text = fmt::format("{}", d->get());
                else
                    return fail(fmt::format("{}: must be a string or a number", name));
                if (name == "device") {
                    spec.line.device = text;
                    continue;
                }
                if (auto e =
                        transport::apply_serial_key(spec, name, text, transport::SerialKeys::port))
                    return fail(*e);
            }
            if (spec.line.device.empty()) return fail("device: missing");
        } else {
            return fail("must be \"DEVICE[,baud=...]\" or a table with device = ...");
        }
        if (auto r = take_spec(*port, spec); !r) return fail(r.error());
        port->where = where;
        set_serial_port(ports, std::move(*port));
    }
    return {};
}

tl::expected<void, std::string> apply_serial_flags(const std::vector<std::string>& flags,
                                                   std::vector<SerialPortConfig>& ports) {
    std::vector<std::string> seen;
    for (const auto& flag : flags) {
        auto port = parse_serial_option(flag);
        if (!port) return Fail(port.error());
        for (const auto& name : seen)
            if (name == port->name)
                return Fail(fmt::format("--serial {}: port {} given twice", flag, name));
        seen.push_back(port->name);
        set_serial_port(ports, std::move(*port));
    }
    return {};
}

void set_serial_port(std::vector<SerialPortConfig>& ports, SerialPortConfig port) {
    for (auto& p : ports)
        if (p.name == port.name) {
            p = std::move(port);
            return;
        }
    ports.push_back(std::move(port));
}

tl::expected<void, std::string> validate_serial(const std::vector<SerialPortConfig>& ports) {
    for (std::size_t i = 0; i < ports.size(); ++i) {
        const auto& p = ports[i];
        if (p.kind == SerialPortConfig::Kind::cpu && p.mode != "hostlink")
            return Fail(
                fmt::format("{}: serial port cpu: mode '{}': the CPU Unit's port serves "
                            "Host Link only (mode=hostlink)",
                            p.where, p.mode));
        if (p.network && p.mode != "gateway")
            return Fail(
                fmt::format("{}: serial port {}: network={} is for gateway ports (the "
                            "Host Link PLCs behind them)",
                            p.where, p.name, *p.network));
        for (std::size_t j = 0; j < i; ++j) {
            if (p.network && ports[j].network == p.network)
                return Fail(fmt::format("{}: serial ports {} and {} both lead to network {}",
                                        p.where, ports[j].name, p.name, *p.network));
            if (ports[j].name == p.name)
                return Fail(fmt::format("{}: serial port {} given twice", p.where, p.name));
            if (ports[j].line.device == p.line.device)
                return Fail(fmt::format("{}: serial ports {} and {} both use {}", p.where,
                                        ports[j].name, p.name, p.line.device));
        }
    }
    return {};
}

}  // namespace fins::finsd
