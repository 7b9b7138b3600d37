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

using config::Entry;
using config::Key;
using config::Type;
using Done = tl::expected<void, std::string>;

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
    bool type_given = false;
    std::vector<Key> keys{located_key("address", d.address, true),
                          {"type", Type::any,
                           [&](const Entry& e) -> Done {
                               auto type = value_type(e.node, e.path);
                               if (!type) return tl::unexpected(type.error());
                               d.type = *type;
                               type_given = true;
                               return {};
                           }},
                          located_key("when", d.when)};
    if (!is_link) keys.emplace_back("kind");  // read above
    // Keys a signal of this kind takes; any other is refused as unknown for the kind.
    const std::pair<std::string_view, double*> numbers[] = {{"value", &d.value},
                                                            {"min", &d.min},
                                                            {"max", &d.max},
                                                            {"period_s", &d.period_s},
                                                            {"phase_s", &d.phase_s},
                                                            {"step", &d.step},
                                                            {"rate", &d.rate},
                                                            {"tau_s", &d.tau_s},
                                                            {"noise", &d.noise},
                                                            {"on_above", &d.on_above},
                                                            {"off_below", &d.off_below},
                                                            {"delay_s", &d.delay_s},
                                                            {"repeat_s", &d.repeat_s}};
    for (const std::string_view name : kind_keys(d.kind)) {
        if (name == "expr" || name == "input" || name == "setpoint")
            keys.push_back(located_key(name, d.input));
        else if (name == "repeat")
            keys.push_back(config::flag_key(name, d.repeat));
        else if (name == "steps")
            keys.emplace_back(name, Type::any, [&](const Entry& e) { return steps(e, d); });
        else if (name == "initial")
            keys.push_back(number_key(name, [&](const Entry&, double n) {
                d.initial = n;
                return Done{};
            }));
        else if (name == "duty")
            // The fraction of each period at max: 0 (always min) to 1 (always max).
            keys.push_back(number_key(name, [&](const Entry& e, double n) -> Done {
                if (!(n >= 0 && n <= 1)) return e.fail(fmt::format("{} is not a fraction 0-1", n));
                d.duty = n;
                return {};
            }));
        for (const auto& [number, field] : numbers)
            if (number == name)
                keys.push_back(number_key(name, [field = field](const Entry&, double n) {
                    *field = n;
                    return Done{};
                }));
    }
    const std::string unknown =
        is_link ? std::string("unknown key")
                : fmt::format("unknown key for kind = \"{}\"", scenario::signal_kind_name(d.kind));
    if (auto r = config::read_table(t, {source_, path, config::At::value, {}, unknown}, keys); !r)
        return r;
    if (!type_given) {
        // A bit address is a bool; a word defaults to int16, as the example.
        auto a = parse_address(d.address.text);
        d.type = a && a->bit ? scenario::ValueType::boolean : scenario::ValueType::int16;
    }
    out_.def.tags.push_back(std::move(d));
    return {};
}

// A steps signal's [[t, value], ...].
tl::expected<void, std::string> ScenarioLoader::steps(const Entry& e, scenario::TagDef& d) const {
    const auto* list = e.node.as_array();
    if (list == nullptr || list->empty()) return fail(e.node, e.path, "must be [[t, value], ...]");
    for (std::size_t i = 0; i < list->size(); ++i) {
        const auto* pair = (*list)[i].as_array();
        const std::string sp = fmt::format("{}[{}]", e.path, i);
        if (pair == nullptr || pair->size() != 2) return fail((*list)[i], sp, "must be [t, value]");
        auto at = number((*pair)[0], sp);
        if (!at) return tl::unexpected(at.error());
        auto value = number((*pair)[1], sp);
        if (!value) return tl::unexpected(value.error());
        d.steps.emplace_back(*at, *value);
    }
    return {};
}

tl::expected<void, std::string> ScenarioLoader::input(const toml::table& t,
                                                      const std::string& path) {
    scenario::InputDef d;
    d.pos = pos(t.source());
    auto r = config::read_table(
        t, {source_, path},
        {located_key("address", d.address, true), {"type", Type::any, [&](const Entry& e) -> Done {
                                                       auto type = value_type(e.node, e.path);
                                                       if (!type)
                                                           return tl::unexpected(type.error());
                                                       d.type = *type;
                                                       return {};
                                                   }}});
    if (!r) return r;
    out_.def.inputs.push_back(std::move(d));
    return {};
}

tl::expected<void, std::string> ScenarioLoader::event(const toml::table& t,
                                                      const std::string& path) {
    scenario::EventDef e;
    e.pos = pos(t.source());
    const auto not_negative = [](std::optional<double>& out) {
        return [&out](const Entry& k, double n) -> Done {
            if (n < 0) return k.fail("must not be negative");
            out = n;
            return {};
        };
    };
    auto r = config::read_table(
        t, {source_, path},
        {{"name", Type::string,
          [&](const Entry& k) -> Done {
              if (k.text().empty()) return k.fail("must not be empty");
              e.name = k.text();
              return {};
          }},
         config::text_key("message", e.message),
         {"fault", Type::string,
          [&](const Entry& k) -> Done {
              auto f = scenario::parse_fault_kind(k.text());
              if (!f)
                  return k.fail(
                      fmt::format("'{}' is not stuck, drift, spike, set, noise, fal, "
                                  "fals, battery, mode, end_code, offline, latency, "
                                  "drop or clock_jump",
                                  k.text()));
              e.fault = *f;
              return {};
          },
          true},
         {"mode", Type::string,
          [&](const Entry& k) -> Done {
              const std::string& s = k.text();
              if (s == "program" || s == "stop")
                  e.mode = scenario::Mode::program;
              else if (s == "monitor")
                  e.mode = scenario::Mode::monitor;
              else if (s == "run")
                  e.mode = scenario::Mode::run;
              else
                  return k.fail(fmt::format("'{}' is not program, monitor or run", s));
              return {};
          }},
         located_key("address", e.address),
         config::integer_key("number", e.number, 1, 511),
         config::integer_key("end_code", e.end_code, 1, 0xFFFF),
         number_key("at_s", not_negative(e.at_s)),
         number_key("every_s", not_negative(e.every_s)),
         number_key("duration_s",
                    [&](const Entry& k, double n) -> Done {
                        if (n < 0) return k.fail("must not be negative");
                        e.duration_s = n;
                        return {};
                    }),
         number_key("value", [&](const Entry&, double n) {
             e.value = n;
             return Done{};
         })});
    if (!r) return r;
    out_.def.events.push_back(std::move(e));
    return {};
}

tl::expected<void, std::string> ScenarioLoader::loop_item(const toml::table& t,
                                                          const std::string& path) {
    scenario::LoopItemDef d;
    d.pos = pos(t.source());
    auto r = config::read_table(
        t, {source_, path},
        {Key("block", Type::integer, config::integer_key("block", d.block, 0, 999).read, true),
         Key("item", Type::integer, config::integer_key("item", d.item, 0, 999).read, true),
         located_key("address", d.address, true)});
    if (!r) return r;
    out_.def.loop_items.push_back(std::move(d));
    return {};
}

}  // namespace fins::finsd
