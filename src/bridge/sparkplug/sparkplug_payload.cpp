#include "bridge/sparkplug/sparkplug_payload.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "fins/values.hpp"

namespace fins::bridge::sparkplug {
namespace pb = finskit::sparkplug::pb;

namespace {

std::int64_t now_ms() {
    using namespace std::chrono;
    return duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count();
}

template <class... F>
struct overloaded : F... {
    using F::operator()...;
};
template <class... F>
overloaded(F...) -> overloaded<F...>;

std::uint64_t ms(std::int64_t t) {
    return t < 0 ? 0 : static_cast<std::uint64_t>(t);
}

// A decoded Sparkplug value as the JSON the write path checks (type, range) like any other.
nlohmann::json to_json(const MetricValue& v) {
    if (const auto* b = std::get_if<bool>(&v)) return *b;
    if (const auto* i = std::get_if<std::int64_t>(&v)) return *i;
    if (const auto* u = std::get_if<std::uint64_t>(&v)) return *u;
    if (const auto* d = std::get_if<double>(&v)) return *d;
    if (const auto* s = std::get_if<std::string>(&v)) return *s;
    return nullptr;
}

}  // namespace

DataType datatype_of(TagType t) noexcept {
    switch (t) {
        case TagType::bits:
            return pb::Boolean;
        case TagType::int16:
            return pb::Int16;
        case TagType::uint16:
        case TagType::hex:  // not a tag type (parse_tag_type refuses it)
            return pb::UInt16;
        case TagType::int32:
            return pb::Int32;
        case TagType::uint32:
            return pb::UInt32;
        case TagType::float32:
            return pb::Float;
        case TagType::float64:
            return pb::Double;
        case TagType::bcd:
            return pb::UInt16;  // 0-9999, as a number
        case TagType::bcd32:
            return pb::UInt32;  // 0-99999999
        case TagType::string:
            return pb::String;
    }
    return pb::Unknown;
}

MetricValue to_metric_value(TagType t, const TagValue& v) {
    const std::span<const std::uint16_t> w{v.words};
    switch (t) {
        case TagType::bits:
            return v.words[0] != 0;
        case TagType::int16:
            return std::int64_t{static_cast<std::int16_t>(v.words[0])};
        case TagType::uint16:
        case TagType::hex:
            return std::uint64_t{v.words[0]};
        case TagType::int32:
            return std::int64_t{words_to_int32(w.first(2)).value_or(0)};
        case TagType::uint32:
            return std::uint64_t{words_to_uint32(w.first(2)).value_or(0)};
        case TagType::float32:
            return static_cast<double>(words_to_float(w.first(2)).value_or(0));
        case TagType::float64:
            return words_to_double(w.first(4)).value_or(0);
        case TagType::bcd: {
            // A word that is not BCD has no number: null + Quality BAD, not a made-up one.
            const auto r = words_to_bcd16(w.first(1));
            return r ? MetricValue{std::uint64_t{*r}} : MetricValue{};
        }
        case TagType::bcd32: {
            const auto r = words_to_bcd32(w.first(2));
            return r ? MetricValue{std::uint64_t{*r}} : MetricValue{};
        }
        case TagType::string:
            return v.text;
    }
    return {};
}

SparkplugPayload::SparkplugPayload(const BridgeConfig& config, std::string group_id)
    : prefix_(config.mqtt.topic_prefix),
      instance_(config.instance),
      node_(std::move(group_id), config.instance) {
    for (const auto& plc : config.plcs) {
        Device d;
        d.plc = &plc;
        std::vector<MetricDef> defs;
        for (std::size_t g = 0; g < plc.groups.size(); ++g) {
            d.group_base.push_back(defs.size());
            for (std::size_t t = 0; t < plc.groups[g].tags.size(); ++t) {
                const auto& tag = plc.groups[g].tags[t];
                defs.push_back(
                    {plc.groups[g].name + "/" + tag.name, datatype_of(tag.type), tag.writable});
                d.tags.emplace_back(g, t);
            }
        }
        d.seen.assign(plc.groups.size(), false);
        node_.define_device(plc.name, std::move(defs));
        devices_.emplace(plc.name, std::move(d));
    }
}

std::vector<std::string> SparkplugPayload::subscriptions() const {
    return node_.subscriptions();
}

bridge::Message SparkplugPayload::bridge_status(bool online) const {
    nlohmann::json j{{"state", online ? "online" : "offline"},
                     {"instance", instance_},
                     {"payload", "sparkplug"},
                     {"edge_node", node_.topic("NBIRTH")}};
    return bridge::Message{prefix_ + "/$bridge/" + instance_ + "/status", j.dump(), 1, true};
}

bridge::Message SparkplugPayload::session_will() {
    awaiting_birth_ = true;
    auto m = node_.next_will(ms(now_ms()));
    return bridge::Message{std::move(m.topic), std::move(m.payload), m.qos, m.retain};
}

bridge::Message SparkplugPayload::session_goodbye() const {
    auto m = node_.death(ms(now_ms()));
    return bridge::Message{std::move(m.topic), std::move(m.payload), m.qos, m.retain};
}

void SparkplugPayload::emit(std::vector<sparkplug::Message>& msgs, const Sink& out) {
    for (auto& m : msgs)
        out(bridge::Message{std::move(m.topic), std::move(m.payload), m.qos, m.retain});
    msgs.clear();
}

void SparkplugPayload::connected(const Sink& out) {
    awaiting_birth_ = false;
    node_.birth(ms(now_ms()), scratch_);
    emit(scratch_, out);
}

void SparkplugPayload::status(const PlcStatus& st, const Sink& out) {
    if (!st.plc) return;
    if (awaiting_birth_) node_.connection_lost();
    // Device online/offline is DBIRTH/DDEATH (chapter 5: a Device that cannot be reached is
    // DDEATH, its metrics stale for host applications, until its next DBIRTH). The DBIRTH
    // waits for the first values of every group (values()): a DBIRTH of nulls with Quality
    // BAD would tell host applications the PLC's values are bad when they are only not read
    // yet.
    const auto it = devices_.find(st.plc->name);
    if (it != devices_.end()) std::fill(it->second.seen.begin(), it->second.seen.end(), false);
    if (!st.online)
        node_.detach(st.plc->name, ms(st.ts_ms), scratch_);
    else if (it != devices_.end() && it->second.seen.empty())
        node_.attach(st.plc->name, ms(st.ts_ms), scratch_);  // no group: nothing to wait for
    emit(scratch_, out);
}

void SparkplugPayload::released(const Plc& plc, const Sink& out) {
    if (awaiting_birth_) node_.connection_lost();
    const auto it = devices_.find(plc.name);
    if (it != devices_.end()) std::fill(it->second.seen.begin(), it->second.seen.end(), false);
    node_.detach(plc.name, ms(now_ms()), scratch_);
    emit(scratch_, out);
}

void SparkplugPayload::values(const GroupSample& s, const Sink& out) {
    if (!s.plc || !s.group) return;
    if (awaiting_birth_) node_.connection_lost();  // keep the values, publish nothing
    const auto it = devices_.find(s.plc->name);
    if (it == devices_.end()) return;
    auto& d = it->second;
    std::size_t g = 0;
    while (g < s.plc->groups.size() && &s.plc->groups[g] != s.group)
        ++g;
    if (g == s.plc->groups.size()) return;
    d.seen[g] = true;
    updates_.clear();
    for (std::size_t t = 0; t < s.tags.size() && t < s.group->tags.size(); ++t) {
        const auto& sample = s.tags[t];
        if (!s.full && !sample.changed && !sample.error) continue;
        MetricUpdate u;
        u.index = d.group_base[g] + t;
        u.timestamp_ms = ms(s.ts_ms);
        if (!sample.error) u.value = to_metric_value(s.group->tags[t].type, sample.value);
        updates_.push_back(std::move(u));
    }
    node_.data(s.plc->name, updates_, ms(s.ts_ms), scratch_);  // kept while not attached
    // A PLC that answers is online: born once every group has values, which ride in the
    // DBIRTH (the values above were kept for it, not published).
    if (!node_.attached(s.plc->name) &&
        std::all_of(d.seen.begin(), d.seen.end(), [](bool b) { return b; }))
        node_.attach(s.plc->name, ms(s.ts_ms), scratch_);
    emit(scratch_, out);
}

void SparkplugPayload::write_response(const Plc& plc, const WriteResponse& r, const Sink& out) {
    (void)out;
    // No response topic in Sparkplug: the read-back value reaches hosts as DDATA with the
    // next poll; a refusal is only logged (and counted).
    if (!r.ok) {
        ++rejected_;
        spdlog::warn("sparkplug: DCMD {} on {} not executed: {}", r.id, plc.name, r.error);
    }
}

void SparkplugPayload::rejected(std::string_view topic, std::string_view reason) {
    ++rejected_;
    spdlog::warn("sparkplug: {} refused: {}", topic, reason);
}

std::optional<ParsedCommand> SparkplugPayload::parse(std::string_view topic,
                                                     std::string_view payload, bool retained) {
    const auto parts = parse_topic(topic);
    if (!parts || parts->group_id != node_.group_id() ||
        parts->edge_node_id != node_.edge_node_id())
        return std::nullopt;
    if (retained) {
        // NCMD and DCMD are never retained (chapter 6): a retained one is stale, not executed.
        return Rejected{
            fmt::format("retained {} (a command is executed once, when sent)", parts->verb)};
    }
    std::vector<Command> cmds;
    node_.on_command(topic, payload, cmds);
    // One command per message: the first Rebirth or write is the answer, every other part of
    // the message is rejected (logged and counted) here; a message with nothing to execute is
    // Rejected with its first reason. A DCMD that sets several metrics executes the first (a
    // host application writing one tag sends one metric).
    std::optional<ParsedCommand> result;
    std::optional<std::string> first_error;
    const auto reject = [&](std::string reason) {
        if (!first_error)
            first_error = std::move(reason);
        else
            rejected(topic, reason);
    };
    for (auto& c : cmds) {
        std::visit(overloaded{
                       [&](const Rebirth&) {
                           if (!result)
                               result = NodeRebirth{};
                           else
                               reject("one command per NCMD: a second Rebirth ignored");
                       },
                       [&](const DeviceWrite& w) {
                           if (result) {
                               reject(fmt::format("one metric per DCMD: {} ignored", w.metric));
                               return;
                           }
                           const auto dev = devices_.find(w.device);
                           if (dev == devices_.end() || w.index >= dev->second.tags.size()) {
                               reject(fmt::format("no metric {} on device {}", w.metric, w.device));
                               return;
                           }
                           const auto [g, t] = dev->second.tags[w.index];
                           WriteCommand wc;
                           wc.plc = w.device;
                           wc.id = fmt::format("dcmd-{}-{}", node_.bd_seq(), ++next_id_);
                           wc.tag = dev->second.plc->groups[g].tags[t].name;
                           wc.value = to_json(w.value);
                           result = std::move(wc);
                       },
                       [&](const CommandError& e) { reject(e.reason); },
                   },
                   c);
    }
    if (!result)
        return Rejected{first_error.value_or(fmt::format("{} sets no metric", parts->verb))};
    if (first_error) rejected(topic, *first_error);
    return result;
}

}  // namespace fins::bridge::sparkplug
