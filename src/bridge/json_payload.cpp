#include "bridge/json_payload.hpp"

#include <array>
#include <charconv>

#include <fmt/format.h>

#include "fins/error.hpp"

namespace fins::bridge {

JsonPayload::JsonPayload(std::string prefix, std::string instance)
    : prefix_(std::move(prefix)), instance_(std::move(instance)) {}

std::vector<std::string> JsonPayload::subscriptions() const {
    return {prefix_ + "/+/write"};
}

Message JsonPayload::bridge_status(bool online) const {
    nlohmann::json j{{"state", online ? "online" : "offline"}, {"instance", instance_}};
    return {fmt::format("{}/$bridge/{}/status", prefix_, instance_), j.dump(), 1, true};
}

nlohmann::json error_json(std::error_code ec) {
    nlohmann::json j{{"error", error_text(ec)}};
    if (ec.category() == end_code_category()) j["end_code"] = fmt::format("{:04X}", ec.value());
    return j;
}

namespace {

// append_json() with the 16-bit integers written by std::to_chars (the same text: the
// decimal number), the hot path of a poll cycle; the other types go to append_json().
void append_value(std::string& b, TagType type, const TagValue& v) {
    std::array<char, 16> digits{};
    const auto put = [&](auto n) {
        const auto r = std::to_chars(digits.data(), digits.data() + digits.size(), n);
        b.append(digits.data(), r.ptr);
    };
    switch (type) {
        case TagType::int16:
            return put(static_cast<std::int16_t>(v.words[0]));
        case TagType::uint16:
            return put(v.words[0]);
        default:
            return append_json(b, type, v);
    }
}

}  // namespace

const JsonPayload::GroupText& JsonPayload::text_of(const GroupSample& s) {
    auto [it, fresh] = groups_.try_emplace(s.group);
    GroupText& t = it->second;
    if (fresh) {
        t.topic = fmt::format("{}/{}/{}", prefix_, s.plc->name, s.group->name);
        for (const Tag& tag : s.group->tags) {
            t.key_ends.push_back(static_cast<std::uint32_t>(t.keys.size()));
            t.keys += '"';
            t.keys += tag.name;  // [A-Za-z0-9_-]: nothing to escape
            t.keys += "\":";
            t.types.push_back(tag.type);
        }
        t.key_ends.push_back(static_cast<std::uint32_t>(t.keys.size()));
    }
    return t;
}

void JsonPayload::values(const GroupSample& s, const Sink& out) {
    // The topic, the `"name":` and the type of every tag are kept once per group, side by
    // side (text_of): a cycle reads no tag's configuration, which for 1,000 PLCs is
    // megabytes the cache would miss at every tag (the type alone was most of the time).
    const GroupText& text = text_of(s);
    std::string& b = buffer_;
    b.clear();
    b += "{\"ts\":";
    std::array<char, 24> digits{};
    b.append(digits.data(),
             std::to_chars(digits.data(), digits.data() + digits.size(), s.ts_ms).ptr);
    b += ",\"values\":{";
    bool first = true;
    for (std::size_t i = 0; i < s.tags.size(); ++i) {
        const TagSample& t = s.tags[i];
        if (!s.full && !t.changed) continue;
        if (!first) b += ',';
        first = false;
        b.append(text.keys, text.key_ends[i], text.key_ends[i + 1] - text.key_ends[i]);
        if (t.error)
            b += error_json(t.error).dump();
        else
            append_value(b, text.types[i], t.value);
    }
    if (first && !s.full) return;  // nothing changed: no message
    b += s.full ? "},\"full\":true}" : "}}";
    out({text.topic, b, 0, false});
}

void JsonPayload::status(const PlcStatus& st, const Sink& out) {
    // The owner: a retained "online" outlives a bridge killed with -9, and is current only
    // while {prefix}/$bridge/{instance}/status says online too (docs/bridge.md).
    nlohmann::json j{{"state", !st.online   ? "offline"
                               : st.failing ? "failing"
                                            : "online"},
                     {"ts", st.ts_ms},
                     {"instance", instance_}};
    if (!st.last_error.empty()) j["error"] = st.last_error;
    out({fmt::format("{}/{}/status", prefix_, st.plc->name), j.dump(), 1, true});
}

void JsonPayload::write_response(const Plc& plc, const WriteResponse& r, const Sink& out) {
    // r.id is the id's JSON text (parse() below): echoed with its JSON type; none: "".
    nlohmann::json id =
        r.id.empty() ? nlohmann::json("") : nlohmann::json::parse(r.id, nullptr, false);
    if (id.is_discarded()) id = r.id;
    nlohmann::json j{{"id", std::move(id)}, {"ok", r.ok}};
    j["end_code"] = r.end_code ? nlohmann::json(fmt::format("{:04X}", *r.end_code)) : nullptr;
    j["value"] = r.value ? *r.value : nlohmann::json(nullptr);
    j["error"] = r.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.error);
    // The id is the peer's, cut to 128 bytes (perhaps inside a UTF-8 character): replace
    // rather than throw.
    out({fmt::format("{}/{}/write/response", prefix_, plc.name),
         j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), 1, false});
}

std::optional<ParsedCommand> JsonPayload::parse(std::string_view topic, std::string_view payload,
                                                bool retained) {
    // {prefix}/{plc}/write
    constexpr std::string_view suffix = "/write";
    if (topic.size() < prefix_.size() + 1 + suffix.size() || !topic.starts_with(prefix_) ||
        topic[prefix_.size()] != '/' || !topic.ends_with(suffix))
        return std::nullopt;
    std::string plc(
        topic.substr(prefix_.size() + 1, topic.size() - prefix_.size() - 1 - suffix.size()));
    const auto refuse = [&](std::string id, std::string error) -> std::optional<ParsedCommand> {
        return Refusal{
            plc, WriteResponse{std::move(id), false, std::nullopt, std::nullopt, std::move(error)}};
    };
    auto j = nlohmann::json::parse(payload, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return refuse("", "the command is not a JSON object");
    // The id keeps its JSON type: 5 and "5" are two ids. It travels as its JSON text (the
    // key of the bridge's id memory) and is echoed as the same JSON value.
    std::string id;
    if (auto f = j.find("id"); f != j.end()) {
        if (f->is_string()) {
            const auto& text = f->get_ref<const std::string&>();
            if (text.size() > max_id_chars)
                return refuse(nlohmann::json(text.substr(0, max_id_chars))
                                  .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                              fmt::format("id longer than {} characters", max_id_chars));
            if (!text.empty()) id = f->dump();
        } else if (f->is_number_integer()) {
            id = f->dump();
        } else {
            return refuse("", "id must be a string or an integer");
        }
    }
    if (id.empty()) return refuse("", "the command has no id");
    if (retained)
        return refuse(id, "retained command refused (a command is executed once, when sent)");
    for (auto& [k, v] : j.items())
        if (k != "id" && k != "tag" && k != "value" && k != "ts")
            return refuse(id, fmt::format("unknown key '{}'", k));
    auto tag = j.find("tag");
    if (tag == j.end() || !tag->is_string()) return refuse(id, "tag must be a string");
    auto value = j.find("value");
    if (value == j.end()) return refuse(id, "the command has no value");
    WriteCommand w;
    w.plc = plc;
    w.id = id;
    w.tag = tag->get<std::string>();
    w.value = *value;
    if (auto ts = j.find("ts"); ts != j.end()) {
        if (!ts->is_number_integer())
            return refuse(id, "ts must be an integer (ms since the epoch)");
        w.ts_ms = ts->get<std::int64_t>();
    }
    return w;
}

}  // namespace fins::bridge
