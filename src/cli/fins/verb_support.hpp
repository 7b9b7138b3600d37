// Private to the `fins` verb files (verbs_plc_data.cpp, verbs_program_area.cpp): number
// parsing, hex text and the verb registration helper they share.
#pragma once

#include <charconv>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "cli/fins/commands.hpp"

namespace fins::cli {

// Decimal or 0x-prefixed hex, at most `max`.
inline std::optional<std::uint32_t> parse_number(const std::string& text, std::uint32_t max) {
    std::string_view s = text;
    int base = 10;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
        base = 16;
        s.remove_prefix(2);
    }
    std::uint32_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
    if (s.empty() || ec != std::errc{} || end != s.data() + s.size() || v > max)
        return std::nullopt;
    return v;
}

inline std::string hex_text(Bytes b) {
    std::string s;
    for (auto byte : b)
        s += fmt::format("{:02X}", byte);
    return s;
}

// Registers a verb whose callback, run once parsing is done, stores `run`'s exit code.
template <class Args>
CLI::App* verb(CLI::App& app, const char* name, const char* help, const GlobalOptions& g,
               int& exit_code, const std::shared_ptr<Args>& args,
               int (*run)(const GlobalOptions&, const Args&, Output&)) {
    auto* c = app.add_subcommand(name, help);
    c->callback([&g, &exit_code, args, run] {
        Output out{g.json};
        exit_code = run(g, *args, out);
    });
    return c;
}

// 03 06 / 03 07 / 03 08: program-read, program-write, program-clear.
void add_program_area_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);

}  // namespace fins::cli
