#include "transport/serial_options.hpp"

#include <charconv>
#include <cstdlib>

#include <fmt/core.h>

namespace fins::transport {
namespace {

constexpr unsigned bauds[] = {300,   600,   1200,  2400,   4800,  9600,
                              19200, 38400, 57600, 115200, 230400};

std::optional<unsigned> parse_unsigned(std::string_view s) {
    unsigned v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
    return v;
}

}  // namespace

bool valid_baud(unsigned baud) noexcept {
    for (auto b : bauds)
        if (b == baud) return true;
    return false;
}

std::optional<std::string> apply_serial_key(SerialSpec& spec, std::string_view key,
                                            std::string_view value, SerialKeys keys) {
    const auto bad = [&](std::string_view what) {
        return fmt::format("{} '{}': {}", key, value, what);
    };
    if (key == "baud") {
        auto v = parse_unsigned(value);
        if (!v || !valid_baud(*v))
            return bad(
                "not one of 300, 600, 1200, 2400, 4800, 9600, 19200, 38400, 57600, "
                "115200, 230400");
        spec.line.baud = *v;
    } else if (key == "parity") {
        if (value == "none" || value == "n" || value == "N")
            spec.line.parity = SerialSettings::Parity::none;
        else if (value == "even" || value == "e" || value == "E")
            spec.line.parity = SerialSettings::Parity::even;
        else if (value == "odd" || value == "o" || value == "O")
            spec.line.parity = SerialSettings::Parity::odd;
        else
            return bad("not none, even or odd");
    } else if (key == "data") {
        auto v = parse_unsigned(value);
        if (!v || (*v != 7 && *v != 8)) return bad("data bits are 7 or 8");
        spec.line.data_bits = *v;
    } else if (key == "stop") {
        auto v = parse_unsigned(value);
        if (!v || (*v != 1 && *v != 2)) return bad("stop bits are 1 or 2");
        spec.line.stop_bits = *v;
    } else if (keys == SerialKeys::port && key == "unit") {
        auto v = parse_unsigned(value);
        if (!v || *v > 31) return bad("Host Link unit numbers are 0-31");
        spec.unit = *v;
    } else if (keys == SerialKeys::port && key == "mode") {
        if (value.empty()) return bad("empty mode");
        spec.mode = std::string(value);
    } else if (keys == SerialKeys::port && key == "timeout") {
        const std::string s(value);
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (s.empty() || end != s.c_str() + s.size() || !(v > 0.0) || v > 3600.0)
            return bad("seconds, more than 0 and at most 3600");
        spec.timeout_seconds = v;
    } else if (keys == SerialKeys::port && key == "network") {
        auto v = parse_unsigned(value);
        if (!v || *v < 1 || *v > 127) return bad("FINS networks are 1-127");
        spec.network = *v;
    } else {
        return fmt::format("unknown serial option '{}' (known: baud, parity, data, stop{})", key,
                           keys == SerialKeys::port ? ", unit, mode, timeout, network" : "");
    }
    return std::nullopt;
}

tl::expected<SerialSpec, std::string> parse_serial_spec(std::string_view text, SerialKeys keys) {
    SerialSpec spec;
    const auto comma = text.find(',');
    spec.line.device = std::string(text.substr(0, comma));
    if (spec.line.device.empty())
        return tl::unexpected(
            fmt::format("no serial device (e.g. {},baud=9600)", example_serial_device));
    std::string_view rest =
        comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
    while (comma != std::string_view::npos) {
        const auto next = rest.find(',');
        const auto item = rest.substr(0, next);
        const auto eq = item.find('=');
        if (eq == std::string_view::npos || eq == 0)
            return tl::unexpected(fmt::format("serial option '{}' is not KEY=VALUE", item));
        if (auto error = apply_serial_key(spec, item.substr(0, eq), item.substr(eq + 1), keys))
            return tl::unexpected(*error);
        if (next == std::string_view::npos) break;
        rest = rest.substr(next + 1);
    }
    return spec;
}

std::string describe_serial(const SerialSettings& line) {
    const char parity = line.parity == SerialSettings::Parity::none   ? 'N'
                        : line.parity == SerialSettings::Parity::even ? 'E'
                                                                      : 'O';
    return fmt::format("{} {} {}{}{}", line.device, line.baud, line.data_bits, parity,
                       line.stop_bits);
}

}  // namespace fins::transport
