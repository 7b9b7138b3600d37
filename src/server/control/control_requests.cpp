// The control channel's PLC verbs (contract in control_requests.hpp).
#include "server/control/control_requests.hpp"

#include <chrono>
#include <optional>
#include <string>

#include <fmt/core.h>

#include "fins/commands/diagnostics.hpp"
#include "plc/plc.hpp"

namespace fins::server {

const char* mode_name(plc::OperatingMode m) noexcept {
    switch (m) {
        case plc::OperatingMode::program:
            return "program";
        case plc::OperatingMode::monitor:
            return "monitor";
        case plc::OperatingMode::run:
            return "run";
    }
    return "run";
}

namespace {

using Json = nlohmann::json;

Json fail(const std::string& message) {
    return control_error(message);
}

std::string hex4(std::uint16_t v) {
    return fmt::format("{:04X}", v);
}

std::optional<bool> flag(const Json& j, const char* key) {
    auto it = j.find(key);
    if (it == j.end() || !it->is_boolean()) return std::nullopt;
    return it->get<bool>();
}

std::optional<std::uint64_t> number(const Json& j, const char* key) {
    auto it = j.find(key);
    if (it == j.end() || !it->is_number_integer() || it->get<std::int64_t>() < 0)
        return std::nullopt;
    return it->get<std::uint64_t>();
}

// An error code as a number or as hex text ("00F7", "0x00F7").
std::optional<std::uint16_t> error_code(const Json& j) {
    auto it = j.find("code");
    if (it == j.end()) return std::nullopt;
    if (it->is_number_integer()) {
        const auto v = it->get<std::int64_t>();
        if (v < 0 || v > 0xFFFF) return std::nullopt;
        return static_cast<std::uint16_t>(v);
    }
    if (!it->is_string()) return std::nullopt;
    std::string text = it->get<std::string>();
    if (text.rfind("0x", 0) == 0 || text.rfind("0X", 0) == 0) text = text.substr(2);
    if (text.empty() || text.size() > 4) return std::nullopt;
    unsigned v = 0;
    for (char c : text) {
        const int d = (c >= '0' && c <= '9')   ? c - '0'
                      : (c >= 'A' && c <= 'F') ? c - 'A' + 10
                      : (c >= 'a' && c <= 'f') ? c - 'a' + 10
                                               : -1;
        if (d < 0) return std::nullopt;
        v = v * 16 + static_cast<unsigned>(d);
    }
    return static_cast<std::uint16_t>(v);
}

// A text field: absent -> "" (allowed), wrong type, too long or not ASCII -> nullopt.
std::optional<std::string> ascii_text(const Json& j, const char* key, std::size_t max) {
    auto it = j.find(key);
    if (it == j.end() || it->is_null()) return std::string{};
    if (!it->is_string()) return std::nullopt;
    std::string s = it->get<std::string>();
    if (s.size() > max) return std::nullopt;
    for (char c : s)
        if (static_cast<unsigned char>(c) >= 0x80) return std::nullopt;
    return s;
}

Json status(plc::Plc& plc) {
    const auto& errors = plc.errors();
    Json list = Json::array();
    const plc::ActiveError* worst = errors.most_serious();
    for (const auto& e : errors.active()) {
        const auto* info = plc::find_error_code(e.code);
        list.push_back({{"code", hex4(e.code)},
                        {"name", info ? std::string(info->name) : "unknown"},
                        {"fatal", info != nullptr && info->fatal},
                        {"message", std::string(e.text())}});
    }
    Json messages = Json::object();
    for (std::size_t n = 0; n < plc::Messages::count; ++n)
        if (plc.messages().registered(n))
            messages[std::to_string(n)] = std::string(plc.messages().text(n));
    Json holder = nullptr;
    if (const auto& h = plc.access_right_holder())
        holder = fmt::format("{}.{}.{}", h->network, h->node, h->unit);
    return Json{{"model", plc.profile().model},
                {"mode", mode_name(plc.mode())},
                {"running", plc.mode() != plc::OperatingMode::program && !errors.has_fatal()},
                {"end_code_flags", hex4(errors.end_code_flags())},
                {"fatal_errors", hex4(errors.fatal_word())},
                {"non_fatal_errors", hex4(errors.non_fatal_word())},
                {"error_code", hex4(worst != nullptr ? worst->code : 0)},
                {"errors", list},
                {"battery_low", errors.battery_low()},
                {"messages", messages},
                {"error_log_records", errors.log_size()},
                {"write_access_log_records", plc.write_access_log().size()},
                {"access_right_holder", holder},
                {"network_write_protection", plc.network_write_protection()},
                {"um_read_protection", plc.um_read_protection()},
                {"memory_card_kbytes", plc.files().card_kbytes()},
                {"memory_cassette", plc.files().cassette_mounted()}};
}

Json raise_fal(plc::Plc& plc, const Json& j, bool fals, plc::ErrorState::TimePoint now) {
    const auto n = number(j, "number");
    if (!n || *n == 0 || *n > max_fal_number) return fail("\"number\" must be 1-511");
    const auto message = ascii_text(j, "message", error_message_size);
    if (!message) return fail("\"message\" must be ASCII text of at most 16 characters");
    const auto number16 = static_cast<std::uint16_t>(*n);
    const bool ok = fals ? plc.errors().raise_fals(number16, *message, now)
                         : plc.errors().raise_fal(number16, *message, now);
    if (!ok) return fail("too many errors present");
    return Json{{"ok", true}};
}

}  // namespace

Json handle_control_request(plc::Plc& plc, const Json& j) {
    const auto now = std::chrono::system_clock::now();
    auto& errors = plc.errors();
    const std::string cmd = j.at("cmd").get<std::string>();
    if (cmd == "status") return Json{{"ok", true}, {"status", status(plc)}};
    if (cmd == "battery_error") {
        const auto on = flag(j, "on");
        if (!on) return fail("\"on\" must be true or false");
        errors.set_battery_low(*on, now);
    } else if (cmd == "fal" || cmd == "fals") {
        return raise_fal(plc, j, cmd == "fals", now);
    } else if (cmd == "error") {
        const auto code = error_code(j);
        const auto* info = code ? plc::find_error_code(*code) : nullptr;
        if (info == nullptr) return fail("\"code\" must be an error code of W342 5-3-27");
        if ((*code >= 0x4101 && *code <= 0x42FF) || (*code >= 0xC101 && *code <= 0xC2FF))
            return fail("use \"fal\" / \"fals\" for FAL and FALS errors");
        if (!errors.raise(*code, now)) return fail("too many errors present");
    } else if (cmd == "clear_errors") {
        if (j.contains("code")) {
            const auto code = error_code(j);
            if (!code) return fail("\"code\" must be a hex error code");
            if (*code == plc::battery_error_code) errors.set_battery_low(false, now);
            errors.clear(*code, now);
        } else {
            errors.set_battery_low(false, now);
            errors.clear_all(now);
        }
    } else if (cmd == "message") {
        const auto n = number(j, "number");
        if (!n || *n >= plc::Messages::count) return fail("\"number\" must be 0-7");
        auto it = j.find("text");
        if (it == j.end() || it->is_null()) {
            plc.messages().clear(static_cast<std::uint8_t>(1U << *n));
        } else {
            const auto text = ascii_text(j, "text", msg_text_size);
            if (!text) return fail("\"text\" must be ASCII text of at most 32 characters");
            plc.messages().set(*n, *text);
        }
    } else if (cmd == "network_write_protection") {
        const auto on = flag(j, "on");
        if (!on) return fail("\"on\" must be true or false");
        plc.set_network_write_protection(*on);
    } else if (cmd == "um_read_protection") {
        // What a Programming Device does: protecting may set a password; releasing a
        // password-protected UM needs it (W342 5-1-3 2602 "incorrect password").
        const auto on = flag(j, "on");
        if (!on) return fail("\"on\" must be true or false");
        const auto it = j.find("password");
        const std::string given = it != j.end() && it->is_string() ? it->get<std::string>() : "";
        if (*on) {
            if (!given.empty()) plc.set_um_password(given);
        } else if (!plc.um_password().empty() && given != plc.um_password()) {
            return fail("incorrect password");
        }
        plc.set_um_read_protection(*on);
    } else if (cmd == "mode") {
        const auto it = j.find("mode");
        const std::string m = it != j.end() && it->is_string() ? it->get<std::string>() : "";
        if (m == "program")
            plc.change_mode(plc::OperatingMode::program, std::chrono::system_clock::now());
        else if (m == "monitor")
            plc.change_mode(plc::OperatingMode::monitor, std::chrono::system_clock::now());
        else if (m == "run")
            plc.change_mode(plc::OperatingMode::run, std::chrono::system_clock::now());
        else
            return fail("\"mode\" must be program, monitor or run");
    } else if (cmd == "release_access_right") {
        plc.set_access_right_holder(std::nullopt);
    } else if (cmd == "card") {
        // Memory card (22 xx disk 8000): the files stay on the host while it is out.
        const auto on = flag(j, "inserted");
        if (!on) return fail("\"inserted\" must be true or false");
        if (!*on) {
            plc.files().remove_card();
        } else {
            const std::uint32_t profile_kb = plc.profile().memory_card_kbytes;
            std::uint32_t kbytes = profile_kb != 0 ? profile_kb : 30720U;
            if (j.contains("kbytes")) {
                const auto kb = number(j, "kbytes");
                if (!kb || *kb == 0 || *kb > 4194303) return fail("\"kbytes\" must be 1-4194303");
                kbytes = static_cast<std::uint32_t>(*kb);
            }
            plc.files().insert_card(kbytes);
        }
    } else if (cmd == "cassette") {
        // CP1H Memory Cassette (22 20 disk 8003): its files stay on the host while it is out.
        const auto on = flag(j, "inserted");
        if (!on) return fail("\"inserted\" must be true or false");
        if (!plc.profile().memory_cassette)
            return fail("the " + plc.profile().name + " has no Memory Cassette slot");
        plc.files().mount_cassette(*on);
    } else {
        return fail("unknown cmd \"" + cmd + "\"");
    }
    return Json{{"ok", true}};
}

Json control_error(const std::string& message) {
    return Json{{"error", message}};
}

}  // namespace fins::server
