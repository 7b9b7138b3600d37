// `fins` verbs for 04 xx mode, 05 xx configuration, 06 20 cycle time, 07 xx clock
// (W342 5-3-13 .. 5-3-16, 5-3-18 .. 5-3-20):
//   fins run [--monitor]                      04 01 FFFF 04 (RUN) / 02 (MONITOR)
//   fins stop                                 04 02 (PROGRAM)
//   fins cpu-data [--section all|area|units]  05 01
//   fins connections [FIRST] [COUNT]          05 02 (FIRST in hex, default 00; COUNT 1-25)
//   fins cycle-time [--reset]                 06 20 01 (read) / 06 20 00 (initialize)
//   fins clock                                07 01
//   fins clock --set "YYYY-MM-DD HH:MM[:SS]" [--day-of-week N | --keep-day-of-week]
//   fins clock --sync                         07 02 with the host's local time
// Exit codes and --json as everywhere else (commands.hpp Output).
#include <charconv>
#include <chrono>
#include <ctime>
#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "codec/hex.hpp"
#include "fins/commands/clock.hpp"
#include "fins/commands/configuration.hpp"
#include "fins/commands/operating_mode.hpp"
#include "fins/commands/status.hpp"

namespace fins::cli {

namespace {

constexpr const char* day_names[] = {"Sun", "Mon", "Tue", "Wed", "Thu", "Fri", "Sat"};

struct ControlArgs {
    bool monitor = false;
    std::string section = "all";
    std::string first_unit = "00";
    unsigned count = max_connection_items;
    bool reset = false;
    std::string set;
    bool sync = false;
    int day_of_week = -1;
    bool keep_day_of_week = false;
};

int run_mode(const GlobalOptions& g, Output& out, bool to_program, bool monitor) {
    int rc = exit_ok;
    const char* mode = to_program ? "PROGRAM" : (monitor ? "MONITOR" : "RUN");
    bool ok = false;
    if (to_program)
        ok = send(g, out, rc, Stop{}).has_value();
    else
        ok = send(g, out, rc, Run{all_programs, monitor ? RunMode::monitor : RunMode::run})
                 .has_value();
    if (!ok) return rc;
    std::string lower(mode);
    for (auto& c : lower)
        c = static_cast<char>(c - 'A' + 'a');
    out.print({{"mode", lower}}, fmt::format("PLC in {} mode\n", mode));
    return exit_ok;
}

std::string row(std::string_view label, const std::string& value) {
    return fmt::format("{:<19}{}\n", label, value);
}

int run_cpu_data(const GlobalOptions& g, Output& out, const std::string& section) {
    CpuUnitDataRead command;
    if (section == "area")
        command.section = CpuUnitDataSection::model_and_area;
    else if (section == "units")
        command.section = CpuUnitDataSection::units_and_info;
    int rc = exit_ok;
    const auto r = send(g, out, rc, command);
    if (!r) return rc;
    nlohmann::json doc = nlohmann::json::object();
    std::string text;
    if (r->has_model_and_area()) {
        const auto& a = r->area;
        doc["model"] = r->model;
        doc["system_version"] = r->system_version;
        doc["dip_switch"] = r->dip_switch;
        doc["largest_em_bank"] = r->largest_em_bank;
        doc["area_data"] = {{"program_kwords", a.program_kwords},
                            {"iom_kbytes", a.iom_kbytes},
                            {"dm_words", a.dm_words},
                            {"timer_counter_kwords", a.timer_counter_kwords},
                            {"em_non_file_banks", a.em_non_file_banks},
                            {"memory_card_type", a.memory_card_type},
                            {"memory_card_kbytes", a.memory_card_kbytes}};
        const char* card = a.memory_card_type == 0x00   ? "none"
                           : a.memory_card_type == 0x04 ? "flash"
                                                        : "other";
        // W342 5-3-15: a CPU Unit without EM answers largest bank 0 and no non-file
        // banks, which is not "bank 0": the text says there is none.
        const bool has_em = r->largest_em_bank != 0 || a.em_non_file_banks != 0;
        text += row("model", r->model) + row("system version", r->system_version) +
                row("DIP switch", fmt::format("0x{:02X}", r->dip_switch)) +
                (has_em ? row("largest EM bank", fmt::format("{:X} hex", r->largest_em_bank))
                        : row("EM", "none")) +
                row("program area", fmt::format("{} K words", a.program_kwords)) +
                row("I/O memory", fmt::format("{} K bytes", a.iom_kbytes)) +
                row("DM words", std::to_string(a.dm_words)) +
                row("timers/counters", fmt::format("{} x 1024", a.timer_counter_kwords)) +
                (has_em ? row("EM (non-file)", plural(a.em_non_file_banks, "bank")) : "") +
                row("memory card", fmt::format("{} (type 0x{:02X}), {} K bytes", card,
                                               a.memory_card_type, a.memory_card_kbytes));
    }
    if (r->has_units_and_info()) {
        nlohmann::json units = nlohmann::json::array();
        std::string listed;
        for (std::size_t n = 0; n < r->bus_units.size(); ++n) {
            const auto word = r->bus_units[n];
            if ((word & cpu_bus_unit_present) == 0) continue;
            const auto id = static_cast<unsigned>(word & ~cpu_bus_unit_present);
            // ID 0: the unit is there but publishes no model ID; print only the unit.
            nlohmann::json unit{{"unit", n}};
            if (id != 0) unit["id"] = fmt::format("0x{:04X}", id);
            units.push_back(unit);
            listed += id != 0 ? fmt::format(", {} (ID 0x{:04X})", n, id) : fmt::format(", {}", n);
        }
        doc["cpu_bus_units"] = units;
        doc["sysmac_bus_masters"] = r->sysmac_bus_masters;
        doc["racks"] = r->racks;
        text += row("CPU Bus Units", listed.empty() ? "none" : listed.substr(2)) +
                row("SYSMAC BUS masters", std::to_string(r->sysmac_bus_masters)) +
                row("racks", std::to_string(r->racks));
    }
    out.print(doc, text);
    return exit_ok;
}

std::optional<std::uint8_t> parse_unit_address(const std::string& s) {
    const auto value = hex::parse_number(s);
    if (!value || *value > 0xFF) return std::nullopt;
    return static_cast<std::uint8_t>(*value);
}

int run_connections(const GlobalOptions& g, Output& out, const ControlArgs& a) {
    const auto first = parse_unit_address(a.first_unit);
    if (!first)
        return out.usage(fmt::format("unit address '{}' is not a hex byte (00-FF)", a.first_unit));
    int rc = exit_ok;
    const auto r = send(g, out, rc, ConnectionDataRead{*first, static_cast<std::uint8_t>(a.count)});
    if (!r) return rc;
    nlohmann::json units = nlohmann::json::array();
    std::string text;
    for (const auto& u : r->units) {
        units.push_back(
            {{"unit_address", fmt::format("{:02X}", u.unit_address)}, {"model", u.model}});
        text += fmt::format("{:02X}  {}\n", u.unit_address, u.model);
    }
    if (r->last_unit_included) text += "(last unit)\n";
    out.print({{"units", units}, {"last_unit_included", r->last_unit_included}}, text);
    return exit_ok;
}

std::string tenths(std::uint32_t v) {
    return fmt::format("{}.{} ms", v / 10, v % 10);
}

int run_cycle_time(const GlobalOptions& g, Output& out, bool reset) {
    int rc = exit_ok;
    const auto r =
        send(g, out, rc,
             CycleTimeRead{reset ? CycleTimeOperation::initialize : CycleTimeOperation::read});
    if (!r) return rc;
    if (reset || !r->times) {
        out.print({{"initialized", true}}, "cycle time maximum and minimum initialized\n");
        return exit_ok;
    }
    const auto& t = *r->times;
    // JSON keeps the manual's 0.1 ms units as integers and adds milliseconds.
    out.print(
        {{"average_ms", t.average / 10.0},
         {"maximum_ms", t.maximum / 10.0},
         {"minimum_ms", t.minimum / 10.0},
         {"unit_0_1ms", {{"average", t.average}, {"maximum", t.maximum}, {"minimum", t.minimum}}}},
        fmt::format("average {}\nmaximum {}\nminimum {}\n", tenths(t.average), tenths(t.maximum),
                    tenths(t.minimum)));
    return exit_ok;
}

// "YYYY-MM-DD HH:MM[:SS]" (also with a 'T'); fields must be numbers, year 1998-2097
// (5-3-19). Ranges inside a field (month 13) are left to the PLC, which answers 110C.
std::optional<ClockWrite> parse_clock(const std::string& s) {
    unsigned f[6] = {0, 0, 0, 0, 0, 0};
    const char seps[] = {'-', '-', ' ', ':', ':'};
    const char* p = s.data();
    const char* end = s.data() + s.size();
    std::size_t n = 0;
    for (; n < 6; ++n) {
        const auto [next, ec] = std::from_chars(p, end, f[n]);
        if (ec != std::errc{} || next == p) return std::nullopt;
        p = next;
        if (p == end) break;
        if (n == 5 || (*p != seps[n] && !(n == 2 && *p == 'T'))) return std::nullopt;
        ++p;
    }
    if (p != end || n < 4) return std::nullopt;  // at least YYYY-MM-DD HH:MM
    if (f[0] < 1998 || f[0] > 2097) return std::nullopt;
    for (std::size_t i = 1; i < 6; ++i)
        if (f[i] > 99) return std::nullopt;
    ClockWrite c;
    c.year = static_cast<std::uint8_t>(f[0] % 100);
    c.month = static_cast<std::uint8_t>(f[1]);
    c.day = static_cast<std::uint8_t>(f[2]);
    c.hour = static_cast<std::uint8_t>(f[3]);
    c.minute = static_cast<std::uint8_t>(f[4]);
    c.second = static_cast<std::uint8_t>(f[5]);
    const std::chrono::year_month_day date{std::chrono::year{static_cast<int>(f[0])},
                                           std::chrono::month{f[1]}, std::chrono::day{f[2]}};
    c.day_of_week = static_cast<std::uint8_t>(
        date.ok() ? std::chrono::weekday{std::chrono::sys_days{date}}.c_encoding() : 0);
    return c;
}

ClockWrite host_clock() {
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    ::localtime_r(&t, &tm);
    ClockWrite c;
    c.year = static_cast<std::uint8_t>(tm.tm_year % 100);
    c.month = static_cast<std::uint8_t>(tm.tm_mon + 1);
    c.day = static_cast<std::uint8_t>(tm.tm_mday);
    c.hour = static_cast<std::uint8_t>(tm.tm_hour);
    c.minute = static_cast<std::uint8_t>(tm.tm_min);
    c.second = static_cast<std::uint8_t>(tm.tm_sec > 59 ? 59 : tm.tm_sec);
    c.day_of_week = static_cast<std::uint8_t>(tm.tm_wday);
    return c;
}

std::string clock_text(const ClockTime& t) {
    return fmt::format("{:04}-{:02}-{:02} {:02}:{:02}:{:02}", full_year(t.year), t.month, t.day,
                       t.hour, t.minute, t.second);
}

int run_clock(const GlobalOptions& g, Output& out, const ControlArgs& a) {
    int rc = exit_ok;
    if (a.set.empty() && !a.sync) {
        const auto r = send(g, out, rc, ClockRead{});
        if (!r) return rc;
        const auto& t = r->time;
        const char* day = t.day_of_week < 7 ? day_names[t.day_of_week] : "?";
        out.print({{"time", clock_text(t)}, {"day_of_week", t.day_of_week}, {"day", day}},
                  fmt::format("{} {}\n", clock_text(t), day));
        return exit_ok;
    }
    std::optional<ClockWrite> setting = a.sync ? host_clock() : parse_clock(a.set);
    if (!setting)
        return out.usage(fmt::format(
            "--set '{}' is not YYYY-MM-DD HH:MM[:SS] with a year from 1998 to 2097", a.set));
    if (a.day_of_week >= 0) setting->day_of_week = static_cast<std::uint8_t>(a.day_of_week);
    if (a.keep_day_of_week) setting->day_of_week.reset();
    if (!send(g, out, rc, *setting)) return rc;
    const ClockTime t{setting->year,
                      setting->month,
                      setting->day,
                      setting->hour,
                      setting->minute,
                      setting->second.value_or(0),
                      0};
    // The keys of `fins clock`: what the clock now reads is "time" either way.
    nlohmann::json doc{{"time", clock_text(t)}};
    std::string text = fmt::format("clock set to {}", clock_text(t));
    if (setting->day_of_week) {
        const char* day = *setting->day_of_week < 7 ? day_names[*setting->day_of_week] : "?";
        doc["day_of_week"] = *setting->day_of_week;
        doc["day"] = day;
        text += fmt::format(" {}", day);
    }
    out.print(doc, text + "\n");
    return exit_ok;
}

}  // namespace

void add_control_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    auto a = std::make_shared<ControlArgs>();
    const auto output = [&g] { return Output{g.json}; };

    auto* run = app.add_subcommand("run", "Start the program: RUN mode (04 01)");
    run->add_flag("--monitor", a->monitor, "MONITOR mode instead of RUN");
    run->callback([&g, &exit_code, a, output] {
        auto out = output();
        exit_code = run_mode(g, out, false, a->monitor);
    });

    auto* stop = app.add_subcommand("stop", "Stop the program: PROGRAM mode (04 02)");
    stop->callback([&g, &exit_code, output] {
        auto out = output();
        exit_code = run_mode(g, out, true, false);
    });

    auto* cpu =
        app.add_subcommand("cpu-data", "Read the CPU Unit's model and configuration (05 01)");
    cpu->add_option("--section", a->section,
                    "all; area = model, version, area data (00); units = CPU Bus Units, racks (01)")
        ->capture_default_str()
        ->check(CLI::IsMember({"all", "area", "units"}));
    cpu->callback([&g, &exit_code, a, output] {
        auto out = output();
        exit_code = run_cpu_data(g, out, a->section);
    });

    auto* conn = app.add_subcommand("connections", "List units and their models (05 02)");
    conn->add_option("first", a->first_unit, "First unit address in hex: 00 CPU, 10-1F, 20-7F, E1")
        ->capture_default_str();
    conn->add_option("count", a->count, "Number of units, 1-25")
        ->capture_default_str()
        ->check(CLI::Range(1, 25));
    conn->callback([&g, &exit_code, a, output] {
        auto out = output();
        exit_code = run_connections(g, out, *a);
    });

    auto* cycle = app.add_subcommand("cycle-time", "Read average/max/min cycle time (06 20)");
    cycle->add_flag("--reset", a->reset, "Initialize the maximum and minimum instead (06 20 00)");
    cycle->callback([&g, &exit_code, a, output] {
        auto out = output();
        exit_code = run_cycle_time(g, out, a->reset);
    });

    auto* clock = app.add_subcommand("clock", "Read (07 01) or set (07 02) the PLC clock");
    auto* set =
        clock->add_option("--set", a->set, "Set to local date and time \"YYYY-MM-DD HH:MM[:SS]\"");
    auto* sync = clock->add_flag("--sync", a->sync, "Set to the host's local time");
    set->excludes(sync);
    auto* dow = clock
                    ->add_option("--day-of-week", a->day_of_week,
                                 "Day of week 0 (Sun) .. 6 (Sat); default: from the date")
                    ->check(CLI::Range(0, 6))
                    ->needs(set);
    clock
        ->add_flag("--keep-day-of-week", a->keep_day_of_week,
                   "Do not send a day of week: the PLC keeps its own (5-3-20)")
        ->needs(set)
        ->excludes(dow);
    clock->callback([&g, &exit_code, a, output] {
        auto out = output();
        exit_code = run_clock(g, out, *a);
    });
}

}  // namespace fins::cli
