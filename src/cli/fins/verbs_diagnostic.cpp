// `fins` verbs for CPU status, messages, access right, error log, write access log and
// forcing (W342 5-3-17, 5-3-21 .. 5-3-31, 5-3-44, 5-3-45):
//   fins status                                  06 01 CPU UNIT STATUS READ
//   fins messages [N...] [--clear]               09 20 MESSAGE READ / CLEAR (default all 0-7)
//   fins fal N                                   09 20 FAL/FALS READ, N = 1-511
//   fins access acquire|force|release            0C 01 / 0C 02 / 0C 03
//   fins error-clear [CODE|all|current]          21 01 (default current = FFFE, all = FFFF)
//   fins error-log [--clear]                     21 02 (all 20 records) / 21 03
//   fins access-log [--clear]                    21 40 (all 20 records) / 21 41
//   fins force set|reset|release|release-on|release-off ADDRESS...
//                                                23 01: 0001 / 0000 / FFFF / 8001 / 8000
//   fins force-cancel                            23 02
// Exit codes and --json as everywhere else (commands.hpp Output). An ERROR LOG READ
// that answers 1104 (fewer records stored than asked for, 5-3-28) is a success here.
#include <array>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "codec/hex.hpp"
#include "fins/address.hpp"
#include "fins/command_table.hpp"
#include "fins/commands/access_right.hpp"
#include "fins/commands/diagnostics.hpp"
#include "fins/commands/error_log.hpp"
#include "fins/commands/forced.hpp"

namespace fins::cli {

namespace {

using Json = nlohmann::json;

struct DiagnosticArgs {
    std::vector<unsigned> numbers;
    bool clear = false;
    unsigned fal = 1;
    std::string access = "acquire";
    std::string code = "current";
    std::string force = "set";
    std::vector<std::string> addresses;
};

// Names of the 06 01 error-word bits (frames 6/0601), bit 0 first.
// clang-format off
constexpr std::array<const char*, 16> fatal_names{
    nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, "FALS error", nullptr,
    "cycle time over", "program error", "I/O setting error", "I/O points overflow",
    "Inner Board error", "duplication error", "I/O bus error", "memory error"};
constexpr std::array<const char*, 16> non_fatal_names{
    nullptr, nullptr, "Special I/O Unit setting error", "CPU Bus Unit setting error",
    "battery error", "SYSMAC BUS error", "Special I/O Unit error", "CPU Bus Unit error",
    "Inner Board error", "I/O verification error", "PLC Setup error", nullptr,
    "basic I/O error", "interrupt task error", "duplex error", "FAL error"};
// clang-format on

std::string hex4(std::uint16_t v) {
    return fmt::format("{:04X}", v);
}

std::string time_text(const LogTime& t) {
    return fmt::format("{}-{:02}-{:02} {:02}:{:02}:{:02}", full_year(t.year), t.month, t.day,
                       t.hour, t.minute, t.second);
}

std::string error_name(std::uint16_t code) {
    const ErrorCodeInfo* info = find_error_code(code);
    if (info == nullptr) return "unknown error";
    if (code >= 0x4101 && code <= 0x42FF) return fmt::format("FAL {}", code - 0x4100);
    if (code >= 0xC101 && code <= 0xC2FF) return fmt::format("FALS {}", code - 0xC100);
    return std::string(info->name);
}

std::string trim(std::string s) {
    while (!s.empty() && (s.back() == ' ' || s.back() == '\0'))
        s.pop_back();
    return s;
}

// The names of the bits set in `word`.
Json bit_names(std::uint16_t word, const std::array<const char*, 16>& names, std::string& text) {
    Json list = Json::array();
    for (unsigned bit = 16; bit-- > 0;) {
        if (((static_cast<unsigned>(word) >> bit) & 1U) == 0) continue;
        const std::string name = names[bit] ? names[bit] : fmt::format("bit {}", bit);
        list.push_back(name);
        text += (text.empty() ? "" : ", ") + name;
    }
    return list;
}

// For commands whose non-zero end codes carry data (0C 01 3001, 21 02 1104).
template <class C>
std::optional<RawResponse> send_raw(const GlobalOptions& g, Output& out, int& rc,
                                    const C& command) {
    std::array<std::uint8_t, max_parameter_size> buffer{};
    ByteWriter w(buffer);
    command.encode(w);
    auto client = open_client(g, out, rc);
    if (!client) return std::nullopt;
    auto r = client->send_raw(C::code, w.written());
    if (!r) {
        rc = out.failure(r.error(), std::string(C::name));
        return std::nullopt;
    }
    rc = exit_ok;
    return std::move(*r);
}

// Sends a command whose answer has no data and prints `doc` / `text`.
template <class C>
int run_simple(const GlobalOptions& g, Output& out, const C& command, const Json& doc,
               const std::string& text) {
    int rc = exit_ok;
    if (!send(g, out, rc, command)) return rc;
    out.print(doc, text);
    return exit_ok;
}

// Prints a log read: `row(record)` gives the record's JSON and its text line.
template <class Response, class Row>
int print_log(Output& out, const Response& log, const char* empty, Row row) {
    Json records = Json::array();
    std::string text;
    for (std::size_t i = 0; i < log.records.size(); ++i) {
        auto [doc, line] = row(log.records[i]);
        records.push_back(doc);
        text += fmt::format("{:>2}  {}\n", i, line);
    }
    if (log.records.empty()) text = std::string(empty) + "\n";
    out.print({{"max_records", log.max_records}, {"stored", log.stored}, {"records", records}},
              text);
    return exit_ok;
}

int run_status(const GlobalOptions& g, Output& out) {
    int rc = exit_ok;
    const auto s = send(g, out, rc, CpuUnitStatusRead{});
    if (!s) return rc;
    const char* mode = s->mode == mode_run       ? "run"
                       : s->mode == mode_monitor ? "monitor"
                                                 : "program";
    std::string fatal_text;
    std::string non_fatal_text;
    Json fatal = bit_names(s->fatal_errors, fatal_names, fatal_text);
    Json non_fatal = bit_names(s->non_fatal_errors, non_fatal_names, non_fatal_text);
    Json messages = Json::array();
    std::string message_text;
    for (unsigned n = 0; n < msg_count; ++n)
        if ((static_cast<unsigned>(s->messages) >> n) & 1U) {
            messages.push_back(n);
            message_text += fmt::format("{}MSG {}", message_text.empty() ? "" : ", ", n);
        }
    const std::string message = trim(s->error_message);
    Json doc{{"running", s->running()},
             {"mode", mode},
             {"flash_writing", (s->status & status_flash_writing) != 0},
             {"battery_present", (s->status & status_battery_present) != 0},
             {"standby", (s->status & status_standby) != 0},
             {"fatal_errors", hex4(s->fatal_errors)},
             {"fatal", fatal},
             {"non_fatal_errors", hex4(s->non_fatal_errors)},
             {"non_fatal", non_fatal},
             {"messages", messages},
             {"error_code", hex4(s->error_code)},
             {"error_message", message}};
    std::string text =
        fmt::format("mode            {} ({})\n", mode, s->running() ? "running" : "stopped");
    text += fmt::format("battery         {}\n",
                        (s->status & status_battery_present) ? "present" : "none");
    text += fmt::format("fatal errors    {}{}\n", hex4(s->fatal_errors),
                        fatal_text.empty() ? "" : "  " + fatal_text);
    text += fmt::format("non-fatal       {}{}\n", hex4(s->non_fatal_errors),
                        non_fatal_text.empty() ? "" : "  " + non_fatal_text);
    text += fmt::format("error code      {}{}\n", hex4(s->error_code),
                        s->error_code ? "  " + error_name(s->error_code) : "");
    text += fmt::format("messages        {}\n", message_text.empty() ? "none" : message_text);
    if (!message.empty()) text += fmt::format("error message   \"{}\"\n", message);
    out.print(doc, text);
    return exit_ok;
}

std::optional<std::uint8_t> message_mask(const std::vector<unsigned>& numbers) {
    if (numbers.empty()) return 0xFF;
    unsigned mask = 0;
    for (unsigned n : numbers) {
        if (n >= msg_count) return std::nullopt;
        mask |= 1U << n;
    }
    return static_cast<std::uint8_t>(mask);
}

int run_messages(const GlobalOptions& g, Output& out, const DiagnosticArgs& a) {
    const auto mask = message_mask(a.numbers);
    if (!mask) return out.usage("message numbers are 0-7");
    int rc = exit_ok;
    if (a.clear)
        return run_simple(g, out, MessageClear{*mask}, {{"cleared", true}, {"mask", *mask}},
                          fmt::format("cleared messages (mask {:02X})\n", *mask));
    const auto r = send(g, out, rc, MessageRead{*mask});
    if (!r) return rc;
    Json list = Json::array();
    std::string text;
    std::size_t i = 0;
    for (unsigned n = 0; n < msg_count; ++n) {
        if (((static_cast<unsigned>(r->messages) >> n) & 1U) == 0 || i >= r->texts.size()) continue;
        const std::string t = trim(r->texts[i++]);
        list.push_back({{"number", n}, {"text", t}});
        text += t.empty() ? fmt::format("MSG {}\n", n) : fmt::format("MSG {}  {}\n", n, t);
    }
    out.print({{"items", list}}, text);
    return exit_ok;
}

int run_fal(const GlobalOptions& g, Output& out, unsigned number) {
    int rc = exit_ok;
    const auto r = send(g, out, rc, FalFalsRead{static_cast<std::uint16_t>(number)});
    if (!r) return rc;
    const std::string message = trim(r->message);
    out.print({{"number", r->number}, {"error_message", message}},
              fmt::format("FAL/FALS {}  \"{}\"\n", r->number, message));
    return exit_ok;
}

int run_access(const GlobalOptions& g, Output& out, const std::string& action) {
    int rc = exit_ok;
    if (action == "force")
        return run_simple(g, out, AccessRightForcedAcquire{}, {{"access_right", "acquired"}},
                          "access right acquired (forced)\n");
    if (action == "release")
        return run_simple(g, out, AccessRightRelease{}, {{"access_right", "released"}},
                          "access right released\n");
    const auto r = send_raw(g, out, rc, AccessRightAcquire{});
    if (!r) return rc;
    if (r->code.ok()) {
        out.print({{"access_right", "acquired"}}, "access right acquired\n");
        return exit_ok;
    }
    const auto holder = AccessRightHolder::decode(r->data);
    if (r->code.end_code() != EndCode::no_access_right || !holder)
        return out.failure(make_error_code(r->code.end_code()),
                           std::string(AccessRightAcquire::name));
    const std::string who = node_text(holder->holder);
    const std::string hint = access_right_hint(holder->holder);
    if (out.json())
        std::printf("%s\n", Json{{"error",
                                  {{"kind", "end_code"},
                                   {"end_code", "3001"},
                                   {"name", "no access right"},
                                   {"holder", who},
                                   {"hint", hint}}}}
                                .dump()
                                .c_str());
    std::fprintf(stderr, "fins: access right held by %s (network.node.unit): 3001\nfins: %s\n",
                 who.c_str(), hint.c_str());
    return exit_end_code;
}

std::optional<std::uint16_t> clear_code(const std::string& s) {
    if (s == "all") return clear_all_errors;
    if (s == "current") return clear_current_error;
    const auto value = hex::parse_number(s, 4);
    if (!value) return std::nullopt;
    return static_cast<std::uint16_t>(*value);
}

int run_error_clear(const GlobalOptions& g, Output& out, const std::string& code_text) {
    const auto code = clear_code(code_text);
    if (!code) return out.usage(fmt::format("'{}' is not all, current or a hex code", code_text));
    const std::string what = *code == clear_all_errors      ? "all errors"
                             : *code == clear_current_error ? "the current error"
                                                            : "error " + hex4(*code);
    return run_simple(g, out, ErrorClear{*code}, {{"cleared", true}, {"code", hex4(*code)}},
                      fmt::format("cleared {} ({})\n", what, hex4(*code)));
}

int run_error_log(const GlobalOptions& g, Output& out, bool clear) {
    if (clear)
        return run_simple(g, out, ErrorLogClear{}, {{"cleared", true}}, "error log cleared\n");
    int rc = exit_ok;
    const ErrorLogRead command{0, log_max_records};
    const auto r = send_raw(g, out, rc, command);
    if (!r) return rc;
    // 5-3-28: fewer records stored than asked for answers 1104 with the stored records.
    if (!r->code.ok() && r->code.end_code() != EndCode::address_range_exceeded)
        return out.failure(make_error_code(r->code.end_code()), std::string(ErrorLogRead::name));
    const auto log = command.decode_response(r->data);
    if (!log) return out.failure(log.error(), std::string(ErrorLogRead::name));
    return print_log(out, *log, "error log empty", [](const ErrorLogRecord& e) {
        const Json doc{{"code", hex4(e.error_code)},
                       {"detail", hex4(e.detail)},
                       {"name", error_name(e.error_code)},
                       {"time", time_text(e.time)}};
        return std::pair{doc, fmt::format("{}  {}  {}  {}", hex4(e.error_code), hex4(e.detail),
                                          time_text(e.time), error_name(e.error_code))};
    });
}

int run_access_log(const GlobalOptions& g, Output& out, bool clear) {
    if (clear)
        return run_simple(g, out, WriteAccessLogClear{}, {{"cleared", true}},
                          "write access log cleared\n");
    int rc = exit_ok;
    const auto log = send(g, out, rc, WriteAccessLogRead{0, log_max_records});
    if (!log) return rc;
    return print_log(out, *log, "write access log empty", [](const WriteAccessRecord& e) {
        const CommandInfo* info = find_command(e.command);
        const std::string name = info ? std::string(info->name) : "unknown command";
        const Json doc{{"source", node_text(e.source)},
                       {"command", hex4(e.command.value())},
                       {"name", name},
                       {"time", time_text(e.time)}};
        return std::pair{doc, fmt::format("{:<11}  {}  {}  {}", node_text(e.source),
                                          hex4(e.command.value()), time_text(e.time), name)};
    });
}

int run_force(const GlobalOptions& g, Output& out, const DiagnosticArgs& a) {
    const ForceAction action = a.force == "set"          ? ForceAction::force_on
                               : a.force == "reset"      ? ForceAction::force_off
                               : a.force == "release"    ? ForceAction::release
                               : a.force == "release-on" ? ForceAction::release_on
                                                         : ForceAction::release_off;
    ForcedSetReset command;
    Json done = Json::array();
    for (const auto& text : a.addresses) {
        auto address = parse_address(text);
        if (!address) return out.usage(bad_address(text, address.error()));
        auto wire = to_memory_address(*address, Access::bit);
        const auto code = wire ? wire->area_code : 0;
        if (!wire || (code != 0x30 && code != 0x31 && code != 0x32 && code != 0x09))
            return out.usage(fmt::format(
                "cannot force '{}': only CIO, W and H bits and T/C completion flags", text));
        command.items.push_back({action, *wire});
        done.push_back(format_address(*address));
    }
    if (command.items.size() > max_forced_items)
        return out.usage(fmt::format("at most {} addresses per request", max_forced_items));
    std::string list;
    for (const auto& d : done)
        list += " " + d.get<std::string>();
    return run_simple(g, out, command, {{"action", a.force}, {"addresses", done}},
                      fmt::format("force {}:{}\n", a.force, list));
}

}  // namespace

void add_diagnostic_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    auto a = std::make_shared<DiagnosticArgs>();
    const auto run = [&g, &exit_code](auto f) {
        return [&g, &exit_code, f] {
            Output out{g.json};
            exit_code = f(out);
        };
    };

    app.add_subcommand("status", "CPU Unit status: mode, errors, messages (06 01)")
        ->callback(run([&g](Output& out) { return run_status(g, out); }));

    auto* msg = app.add_subcommand("messages", "Read (or --clear) MSG messages 0-7 (09 20)");
    msg->add_option("numbers", a->numbers, "Message numbers 0-7 (default: all)")
        ->check(CLI::Range(0, 7));
    msg->add_flag("--clear", a->clear, "MESSAGE CLEAR instead of MESSAGE READ");
    msg->callback(run([&g, a](Output& out) { return run_messages(g, out, *a); }));

    auto* fal = app.add_subcommand("fal", "Read the message of FAL/FALS number N (09 20)");
    fal->add_option("number", a->fal, "FAL/FALS number 1-511")
        ->required()
        ->check(CLI::Range(1, 511));
    fal->callback(run([&g, a](Output& out) { return run_fal(g, out, a->fal); }));

    auto* access = app.add_subcommand(
        "access", "Access right: acquire (0C 01), force (0C 02), release (0C 03)");
    access->add_option("action", a->access, "acquire, force or release")
        ->required()
        ->check(CLI::IsMember({"acquire", "force", "release"}));
    access->callback(run([&g, a](Output& out) { return run_access(g, out, a->access); }));

    auto* clear = app.add_subcommand("error-clear", "Clear an error (21 01)");
    clear->add_option("code", a->code, "current (FFFE, default), all (FFFF) or a hex error code")
        ->capture_default_str();
    clear->callback(run([&g, a](Output& out) { return run_error_clear(g, out, a->code); }));

    auto* elog = app.add_subcommand("error-log", "Read (21 02) or --clear (21 03) the error log");
    elog->add_flag("--clear", a->clear, "ERROR LOG CLEAR");
    elog->callback(run([&g, a](Output& out) { return run_error_log(g, out, a->clear); }));

    auto* alog = app.add_subcommand("access-log",
                                    "Read (21 40) or --clear (21 41) the FINS write access log");
    alog->add_flag("--clear", a->clear, "FINS WRITE ACCESS LOG CLEAR");
    alog->callback(run([&g, a](Output& out) { return run_access_log(g, out, a->clear); }));

    auto* force =
        app.add_subcommand("force", "Force bits/flags ON or OFF, or release them (23 01)");
    force->add_option("action", a->force, "set, reset, release, release-on or release-off")
        ->required()
        ->check(CLI::IsMember({"set", "reset", "release", "release-on", "release-off"}));
    force
        ->add_option("addresses", a->addresses,
                     "Bits (CIO10.13, W0.01, H5.00) or T/C flags (T5, C3)")
        ->required();
    force->callback(run([&g, a](Output& out) { return run_force(g, out, *a); }));

    app.add_subcommand("force-cancel", "Release every forced bit and flag (23 02)")
        ->callback(run([&g](Output& out) {
            return run_simple(g, out, ForcedSetResetCancel{}, {{"cancelled", true}},
                              "all forced bits released\n");
        }));
}

}  // namespace fins::cli
