// [[scenario.signal]], [[scenario.link]], [[scenario.input]] and [[scenario.event]]
// entries of a [scenario] table (config_scenario_loader.hpp).
#include <algorithm>
#include <limits>

#include "fins/address.hpp"
#include "finsd/config_scenario_loader.hpp"
#include "finsd/config_values.hpp"

namespace fins::finsd {

namespace {

using scenario::SignalKind;

// Keys a signal of each kind takes beyond address, type, kind and when.
std::vector<std::string_view> kind_keys(SignalKind kind) {
    switch (kind) {
        case SignalKind::constant:
            return {"value"};
        case SignalKind::square:
            return {"min", "max", "period_s", "phase_s", "duty"};
        case SignalKind::sine:
        case SignalKind::triangle:
        case SignalKind::sawtooth:
            return {"min", "max", "period_s", "phase_s"};
        case SignalKind::ramp:
            return {"min", "max", "period_s", "repeat"};
        case SignalKind::random_walk:
            return {"min", "max", "step", "initial"};
        case SignalKind::steps:
            return {"steps", "repeat_s", "initial"};
        case SignalKind::counter:
            return {"input", "rate", "min", "max", "initial"};
        case SignalKind::totaliser:
            return {"input", "initial"};
        case SignalKind::lag:
            return {"setpoint", "tau_s", "noise", "initial"};
        case SignalKind::hysteresis:
            return {"input", "on_above", "off_below"};
        case SignalKind::link:
            return {"expr", "delay_s"};
    }
    return {};
}

}  // namespace

tl::expected<void, std::string> ScenarioLoader::tag(const toml::table& t, const std::string& path,
                                                    bool is_link) {
    scenario::TagDef d;
    d.pos = pos(t.source());
    d.kind = SignalKind::link;
    if (!is_link) {
        const auto* kind = t.get("kind");
        if (kind == nullptr) return fail_at(t.source(), path, "kind: missing");
        auto s = text(*kind, path + ".kind");
        if (!s) return tl::unexpected(s.error());
        auto k = scenario::parse_signal_kind(*s);
        if (!k || *k == SignalKind::link)
            return fail(*kind, path + ".kind",
                        fmt::format("'{}' is not constant, sine, square, triangle, sawtooth, "
                                    "ramp, random_walk, steps, counter, totaliser, lag or "
                                    "hysteresis",
                                    *s));
        d.kind = *k;
    }
    const auto allowed = kind_keys(d.kind);
    bool type_given = false;
    for (const auto& [key_ptr, node_ptr] : in_file_order(t)) {
        const std::string k(key_ptr->str());
        const toml::node& v = *node_ptr;
        const std::string p = path + "." + k;
        if (k == "kind" && !is_link) continue;
        if (k == "address") {
            auto a = located_text(v, p);
            if (!a) return tl::unexpected(a.error());
            d.address = *a;
        } else if (k == "type") {
            auto type = value_type(v, p);
            if (!type) return tl::unexpected(type.error());
            d.type = *type;
            type_given = true;
        } else if (k == "when") {
            auto e = located_text(v, p);
            if (!e) return tl::unexpected(e.error());
            d.when = *e;
        } else if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
            return fail(*key_ptr, p,
                        is_link ? std::string("unknown key")
                                : fmt::format("unknown key for kind = \"{}\"",
                                              scenario::signal_kind_name(d.kind)));
        } else if (k == "expr" || k == "input" || k == "setpoint") {
            auto e = located_text(v, p);
            if (!e) return tl::unexpected(e.error());
            d.input = *e;
        } else if (k == "repeat") {
            const auto* b = v.as_boolean();
            if (b == nullptr) return fail(v, p, "must be true or false");
            d.repeat = b->get();
        } else if (k == "steps") {
            const auto* list = v.as_array();
            if (list == nullptr || list->empty()) return fail(v, p, "must be [[t, value], ...]");
            for (std::size_t i = 0; i < list->size(); ++i) {
                const auto* pair = (*list)[i].as_array();
                const std::string sp = fmt::format("{}[{}]", p, i);
                if (pair == nullptr || pair->size() != 2)
                    return fail((*list)[i], sp, "must be [t, value]");
                auto at = number((*pair)[0], sp);
                if (!at) return tl::unexpected(at.error());
                auto value = number((*pair)[1], sp);
                if (!value) return tl::unexpected(value.error());
                d.steps.emplace_back(*at, *value);
            }
        } else {
            auto n = number(v, p);
            if (!n) return tl::unexpected(n.error());
            if (k == "value")
                d.value = *n;
            else if (k == "min")
                d.min = *n;
            else if (k == "max")
                d.max = *n;
            else if (k == "period_s")
                d.period_s = *n;
            else if (k == "phase_s")
                d.phase_s = *n;
            else if (k == "duty") {
                // The fraction of each period at max: 0 (always min) to 1 (always max).
                if (!(*n >= 0 && *n <= 1))
                    return fail(v, p, fmt::format("{} is not a fraction 0-1", *n));
                d.duty = *n;
            } else if (k == "step")
                d.step = *n;
            else if (k == "rate")
                d.rate = *n;
            else if (k == "tau_s")
                d.tau_s = *n;
            else if (k == "noise")
                d.noise = *n;
            else if (k == "on_above")
                d.on_above = *n;
            else if (k == "off_below")
                d.off_below = *n;
            else if (k == "delay_s")
                d.delay_s = *n;
            else if (k == "initial")
                d.initial = *n;
            else if (k == "repeat_s")
                d.repeat_s = *n;
        }
    }
    if (d.address.text.empty()) return fail_at(t.source(), path, "address: missing");
    if (!type_given) {
        // A bit address is a bool; a word defaults to int16, as the example.
        auto a = parse_address(d.address.text);
        d.type = a && a->bit ? scenario::ValueType::boolean : scenario::ValueType::int16;
    }
    out_.def.tags.push_back(std::move(d));
    return {};
}

tl::expected<void, std::string> ScenarioLoader::input(const toml::table& t,
                                                      const std::string& path) {
    scenario::InputDef d;
    d.pos = pos(t.source());
    for (const auto& [key_ptr, node_ptr] : in_file_order(t)) {
        const std::string k(key_ptr->str());
        const std::string p = path + "." + k;
        if (k == "address") {
            auto a = located_text(*node_ptr, p);
            if (!a) return tl::unexpected(a.error());
            d.address = *a;
        } else if (k == "type") {
            auto type = value_type(*node_ptr, p);
            if (!type) return tl::unexpected(type.error());
            d.type = *type;
        } else {
            return fail(*key_ptr, p, "unknown key");
        }
    }
    if (d.address.text.empty()) return fail_at(t.source(), path, "address: missing");
    out_.def.inputs.push_back(std::move(d));
    return {};
}

tl::expected<void, std::string> ScenarioLoader::event(const toml::table& t,
                                                      const std::string& path) {
    scenario::EventDef e;
    e.pos = pos(t.source());
    bool fault_given = false;
    for (const auto& [key_ptr, node_ptr] : in_file_order(t)) {
        const std::string k(key_ptr->str());
        const toml::node& v = *node_ptr;
        const std::string p = path + "." + k;
        if (k == "name" || k == "message" || k == "fault" || k == "mode") {
            auto s = text(v, p);
            if (!s) return tl::unexpected(s.error());
            if (k == "name") {
                if (s->empty()) return fail(v, p, "must not be empty");
                e.name = *s;
            } else if (k == "message") {
                e.message = *s;
            } else if (k == "fault") {
                auto f = scenario::parse_fault_kind(*s);
                if (!f)
                    return fail(v, p,
                                fmt::format("'{}' is not stuck, drift, spike, set, noise, fal, "
                                            "fals, battery, mode, end_code, offline, latency, "
                                            "drop or clock_jump",
                                            *s));
                e.fault = *f;
                fault_given = true;
            } else {
                if (*s == "program" || *s == "stop")
                    e.mode = scenario::Mode::program;
                else if (*s == "monitor")
                    e.mode = scenario::Mode::monitor;
                else if (*s == "run")
                    e.mode = scenario::Mode::run;
                else
                    return fail(v, p, fmt::format("'{}' is not program, monitor or run", *s));
            }
        } else if (k == "address") {
            auto a = located_text(v, p);
            if (!a) return tl::unexpected(a.error());
            e.address = *a;
        } else if (k == "number") {
            auto n = integer(v, p, 1, 511);
            if (!n) return tl::unexpected(n.error());
            e.number = static_cast<std::uint16_t>(*n);
        } else if (k == "end_code") {
            auto n = integer(v, p, 1, 0xFFFF);
            if (!n) return tl::unexpected(n.error());
            e.end_code = static_cast<std::uint16_t>(*n);
        } else if (k == "at_s" || k == "every_s" || k == "duration_s" || k == "value") {
            auto n = number(v, p);
            if (!n) return tl::unexpected(n.error());
            if (k != "value" && *n < 0) return fail(v, p, "must not be negative");
            if (k == "at_s")
                e.at_s = *n;
            else if (k == "every_s")
                e.every_s = *n;
            else if (k == "duration_s")
                e.duration_s = *n;
            else
                e.value = *n;
        } else {
            return fail(*key_ptr, p, "unknown key");
        }
    }
    if (!fault_given) return fail_at(t.source(), path, "fault: missing");
    out_.def.events.push_back(std::move(e));
    return {};
}

tl::expected<void, std::string> ScenarioLoader::loop_item(const toml::table& t,
                                                          const std::string& path) {
    scenario::LoopItemDef d;
    d.pos = pos(t.source());
    for (const auto& [key_ptr, node_ptr] : in_file_order(t)) {
        const std::string k(key_ptr->str());
        const std::string p = path + "." + k;
        if (k == "address") {
            auto a = located_text(*node_ptr, p);
            if (!a) return tl::unexpected(a.error());
            d.address = *a;
        } else if (k == "block" || k == "item") {
            auto n = integer(*node_ptr, p, 0, 999);
            if (!n) return tl::unexpected(n.error());
            (k == "block" ? d.block : d.item) = *n;
        } else {
            return fail(*key_ptr, p, "unknown key");
        }
    }
    if (d.block < 0) return fail_at(t.source(), path, "block: missing");
    if (d.item < 0) return fail_at(t.source(), path, "item: missing");
    if (d.address.text.empty()) return fail_at(t.source(), path, "address: missing");
    out_.def.loop_items.push_back(std::move(d));
    return {};
}

}  // namespace fins::finsd
