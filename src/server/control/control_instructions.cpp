// The control channel's send / recv / sendcmd / instructions verbs
// (control_instructions.hpp).
#include "server/control/control_instructions.hpp"

#include <variant>

#include <fmt/format.h>

#include "codec/hex.hpp"
#include "server/control/control.hpp"
#include "server/instructions/instruction_schedule.hpp"
#include "server/instructions/network_instructions.hpp"

namespace fins::server {

namespace {

using Json = nlohmann::json;

std::string hex4(std::uint16_t v) {
    return fmt::format("{:04X}", v);
}

std::optional<std::vector<std::uint8_t>> parse_hex(const std::string& text) {
    return hex::parse_bytes(text, " :_");
}

// A non-negative integer key with a default; nullopt when present but not one.
std::optional<std::uint64_t> unsigned_key(const Json& j, const char* key, std::uint64_t fallback) {
    const auto it = j.find(key);
    if (it == j.end()) return fallback;
    if (!it->is_number_integer() || it->get<std::int64_t>() < 0) return std::nullopt;
    return it->get<std::uint64_t>();
}

// The request, or why it cannot be read. Ranges are the engine's to check (0400).
std::variant<InstructionRequest, std::string> read_request(InstructionKind kind, const Json& j) {
    InstructionRequest r;
    r.kind = kind;
    const auto text = [&](const char* key) -> std::optional<std::string> {
        const auto it = j.find(key);
        if (it == j.end() || !it->is_string()) return std::nullopt;
        return it->get<std::string>();
    };
    const auto dest = text("dest");
    const auto node = dest ? parse_destination(*dest) : std::nullopt;
    if (!node) return std::string("\"dest\" must be NET.NODE.UNIT (network 0-127, node 0-255)");
    r.destination = *node;
    const auto timeout = unsigned_key(j, "timeout", 0);
    const auto retries = unsigned_key(j, "retries", 0);
    if (!timeout || *timeout > 0xFFFF) return std::string("\"timeout\" must be 0-65535 (0.1 s)");
    if (!retries || *retries > 255) return std::string("\"retries\" must be 0-15");
    r.options.timeout = static_cast<std::uint16_t>(*timeout);
    r.options.retries = static_cast<unsigned>(*retries);
    if (const auto it = j.find("no_response"); it != j.end()) {
        if (!it->is_boolean()) return std::string("\"no_response\" must be true or false");
        r.options.no_response = it->get<bool>();
    }
    if (kind == InstructionKind::sendcmd) {
        const auto hex = text("command");
        auto bytes = hex ? parse_hex(*hex) : std::nullopt;
        if (!bytes) return std::string("\"command\" must be hex bytes: MRC SRC parameters");
        r.command = std::move(*bytes);
        return r;
    }
    for (const auto& [key, out] : {std::pair{"local", &r.local}, std::pair{"remote", &r.remote}}) {
        const auto t = text(key);
        const auto a = t ? parse_address(*t) : Result<Address>{Unexpected(std::error_code{})};
        if (!a) return fmt::format("\"{}\" must be a word address such as D100", key);
        *out = *a;
    }
    const auto count = unsigned_key(j, "count", 1);
    if (!count || *count > 0xFFFF) return std::string("\"count\" must be a number of words");
    r.count = static_cast<std::uint16_t>(*count);
    return r;
}

Json result_json(InstructionKind kind, const InstructionResult& r) {
    Json out{{"instruction", instruction_kind_name(kind)},
             {"done", r.done()},
             {"error_id", hex4(r.error_id)},
             {"error_id_ex", hex4(r.error_id_ex)},
             {"end_code", r.end_code ? Json(hex4(*r.end_code)) : Json(nullptr)},
             {"port", r.port < 0 ? Json(nullptr) : Json(r.port)},
             {"transmissions", r.transmissions},
             {"detail", r.detail}};
    if (kind == InstructionKind::recv) out["words"] = r.words;
    if (kind == InstructionKind::sendcmd) {
        std::string hex;
        for (const auto b : r.response)
            hex += fmt::format("{:02X}", b);
        out["response"] = hex;
    }
    return out;
}

}  // namespace

bool handle_instruction_request(NetworkInstructions* engine,
                                const std::vector<ScheduleEntry>& schedule, const Json& j,
                                const ControlReply& reply) {
    const std::string cmd = j.at("cmd").get<std::string>();
    const bool status = cmd == "instructions";
    const auto kind = parse_instruction_kind(cmd);
    if (!status && (!kind || cmd == "rcv" || cmd == "cmnd")) return false;
    if (engine == nullptr) {
        reply(Json{{"error", "this finsd runs no network instructions"}});
        return true;
    }
    if (status) {
        const auto& c = engine->counters();
        Json entries = Json::array();
        for (const auto& entry : schedule) {
            const auto& e = entry.schedule->counters(entry.index);
            entries.push_back({{"runs", e.runs},
                               {"done", e.done},
                               {"errors", e.errors},
                               {"skipped", e.skipped},
                               {"last_error_id", hex4(e.last_error_id)},
                               {"last_error_id_ex", hex4(e.last_error_id_ex)}});
        }
        reply(Json{{"ok", true},
                   {"schedule", entries},
                   {"instructions",
                    {{"in_flight", engine->in_flight()},
                     {"available", engine->available()},
                     {"limit", max_instructions},
                     {"started", c.started},
                     {"done", c.done},
                     {"errors", c.errors},
                     {"timeouts", c.timeouts},
                     {"retransmissions", c.retransmissions},
                     {"unmatched_responses", c.unmatched}}}});
        return true;
    }
    auto request = read_request(*kind, j);
    if (auto* why = std::get_if<std::string>(&request)) {
        reply(Json{{"error", *why}});
        return true;
    }
    engine->start(std::move(std::get<InstructionRequest>(request)),
                  [reply, k = *kind](const InstructionResult& r) {
                      Json answer{{"ok", r.done()}, {"result", result_json(k, r)}};
                      if (!r.done())
                          answer["error"] = fmt::format("ErrorID {:04X} ErrorIDEx {:04X}: {}",
                                                        r.error_id, r.error_id_ex, r.detail);
                      reply(std::move(answer));
                  });
    return true;
}

}  // namespace fins::server
