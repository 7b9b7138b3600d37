// The [scenario] loader (contract in config_scenario.hpp). Each key is read with its type
// and checked; keys that do not apply to a signal's kind are refused like unknown ones.
#include "cli/finsd/config_scenario.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "cli/finsd/config_values.hpp"
#include "plc/plc.hpp"
#include "scenario/scenario.hpp"

namespace fins::cli::finsd {

namespace {

using scenario::SignalKind;
using Unexpected = tl::unexpected<std::string>;

// Keys a signal of each kind takes beyond address, type, kind and when.
std::vector<std::string_view> kind_keys(SignalKind kind) {
    switch (kind) {
        case SignalKind::constant:
            return {"value"};
        case SignalKind::sine:
        case SignalKind::square:
        case SignalKind::triangle:
        case SignalKind::sawtooth:
            return {"min", "max", "period_s", "phase_s", "duty"};
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

class ScenarioLoader {
  public:
    ScenarioLoader(ScenarioConfig& out, std::string_view source)
        : out_(out), source_(source), index_(static_cast<std::uint32_t>(out.sources.size())) {
        out_.sources.emplace_back(source);
    }

    tl::expected<void, std::string> table(const toml::node& node, const std::string& path,
                                          bool allow_file) {
        const auto* t = node.as_table();
        if (t == nullptr) return fail(node, path, "must be a table");
        // `file` first: what the table adds comes after what the file holds.
        if (const auto* file = t->get("file")) {
            if (!allow_file)
                return fail(*file, path + ".file", "a scenario file cannot name another");
            const auto* name = file->as_string();
            if (name == nullptr || name->get().empty())
                return fail(*file, path + ".file", "must be a file name");
            std::filesystem::path p = name->get();
            if (p.is_relative()) p = std::filesystem::path(source_).parent_path() / p;
            auto root = parse_file(p);
            if (!root) return tl::unexpected(root.error());
            const auto* inner = root->get("scenario");
            if (inner == nullptr)
                return fail(*file, path + ".file",
                            fmt::format("{} has no [scenario] table", p.string()));
            ScenarioLoader nested(out_, p.string());
            if (auto r = nested.table(*inner, "scenario", false); !r) return r;
        }
        for (const auto& [key_ptr, node_ptr] : in_file_order(*t)) {
            const std::string k(key_ptr->str());
            const toml::node& v = *node_ptr;
            const std::string p = path + "." + k;
            tl::expected<void, std::string> r;
            auto& def = out_.def;
            if (k == "file") {
                continue;
            } else if (k == "seed") {
                auto n = integer(v, p, 0, std::numeric_limits<std::int64_t>::max());
                if (!n) return tl::unexpected(n.error());
                def.seed = static_cast<std::uint64_t>(*n);
            } else if (k == "tick_ms") {
                auto n = integer(v, p, 1, 3'600'000);
                if (!n) return tl::unexpected(n.error());
                def.tick_s = static_cast<double>(*n) / 1000.0;
            } else if (k == "time") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                if (*s != "real" && *s != "virtual")
                    return fail(v, p, fmt::format("'{}' is not real or virtual", *s));
                def.virtual_time = *s == "virtual";
            } else if (k == "time_scale") {
                auto d = number(v, p);
                if (!d) return tl::unexpected(d.error());
                if (!(*d > 0 && *d <= 1000)) return fail(v, p, "must be above 0 and at most 1000");
                def.time_scale = *d;
            } else if (k == "signal" || k == "link" || k == "input" || k == "event") {
                const auto* list = v.as_array();
                if (list == nullptr)
                    return fail(v, p, fmt::format("must be an array of tables ([[{}]])", p));
                for (std::size_t i = 0; i < list->size(); ++i) {
                    const auto& item = (*list)[i];
                    const std::string ip = fmt::format("{}[{}]", p, i);
                    if (!item.is_table()) return fail(item, ip, "must be a table");
                    if (k == "event")
                        r = event(*item.as_table(), ip);
                    else if (k == "input")
                        r = input(*item.as_table(), ip);
                    else
                        r = tag(*item.as_table(), ip, k == "link");
                    if (!r) return r;
                }
            } else {
                return fail(*key_ptr, p, "unknown key");
            }
        }
        return {};
    }

    static tl::expected<toml::table, std::string> parse_file(const std::filesystem::path& file) {
        std::ifstream in(file, std::ios::binary);
        if (!in) return Unexpected(fmt::format("{}: cannot read the file", file.string()));
        std::ostringstream text;
        text << in.rdbuf();
        try {
            return toml::parse(text.str(), file.string());
        } catch (const toml::parse_error& e) {
            return Unexpected(fmt::format("{}:{}:{}: {}", file.string(), e.source().begin.line,
                                          e.source().begin.column, e.description()));
        }
    }

  private:
    scenario::SourcePos pos(const toml::source_region& r) const {
        return {static_cast<std::uint32_t>(r.begin.line),
                static_cast<std::uint32_t>(r.begin.column), index_};
    }
    Unexpected fail(const toml::node& node, const std::string& path,
                    std::string_view message) const {
        return fail_at(node.source(), path, message);
    }
    Unexpected fail(const toml::key& key, const std::string& path, std::string_view message) const {
        return fail_at(key.source(), path, message);
    }
    Unexpected fail_at(const toml::source_region& r, const std::string& path,
                       std::string_view message) const {
        return Unexpected(
            fmt::format("{}:{}:{}: {}: {}", source_, r.begin.line, r.begin.column, path, message));
    }
    tl::expected<std::int64_t, std::string> integer(const toml::node& v, const std::string& p,
                                                    std::int64_t lo, std::int64_t hi) const {
        const auto* n = v.as_integer();
        if (n == nullptr) return fail(v, p, "must be an integer");
        if (n->get() < lo || n->get() > hi)
            return fail(v, p, fmt::format("{} is not {}-{}", n->get(), lo, hi));
        return n->get();
    }
    tl::expected<double, std::string> number(const toml::node& v, const std::string& p) const {
        if (const auto* i = v.as_integer()) return static_cast<double>(i->get());
        if (const auto* f = v.as_floating_point()) {
            if (!std::isfinite(f->get())) return fail(v, p, "must be a finite number");
            return f->get();
        }
        return fail(v, p, "must be a number");
    }
    tl::expected<std::string, std::string> text(const toml::node& v, const std::string& p) const {
        const auto* s = v.as_string();
        if (s == nullptr) return fail(v, p, "must be a string");
        return s->get();
    }
    tl::expected<scenario::Text, std::string> located_text(const toml::node& v,
                                                           const std::string& p) const {
        auto s = text(v, p);
        if (!s) return tl::unexpected(s.error());
        if (s->empty()) return fail(v, p, "must not be empty");
        return scenario::Text{*s, pos(v.source())};
    }
    tl::expected<scenario::ValueType, std::string> value_type(const toml::node& v,
                                                              const std::string& p) const {
        auto s = text(v, p);
        if (!s) return tl::unexpected(s.error());
        auto type = scenario::parse_value_type(*s);
        if (!type)
            return fail(v, p,
                        fmt::format("'{}' is not int16, uint16, int32, uint32, float, "
                                    "double, bcd or bool",
                                    *s));
        return *type;
    }

    tl::expected<void, std::string> tag(const toml::table& t, const std::string& path,
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
                if (list == nullptr || list->empty())
                    return fail(v, p, "must be [[t, value], ...]");
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
                else if (k == "duty")
                    d.duty = *n;
                else if (k == "step")
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

    tl::expected<void, std::string> input(const toml::table& t, const std::string& path) {
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

    tl::expected<void, std::string> event(const toml::table& t, const std::string& path) {
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

    ScenarioConfig& out_;
    std::string source_;
    std::uint32_t index_;
};

}  // namespace

tl::expected<ScenarioConfig, std::string> load_scenario_table(const toml::node& node,
                                                              std::string_view source,
                                                              const std::string& path) {
    ScenarioConfig config;
    config.reload_file = std::string(source);
    ScenarioLoader loader(config, source);
    if (auto r = loader.table(node, path, true); !r) return tl::unexpected(r.error());
    return config;
}

tl::expected<ScenarioConfig, std::string> load_scenario_file(const std::filesystem::path& file) {
    auto root = ScenarioLoader::parse_file(file);
    if (!root) return tl::unexpected(root.error());
    const auto* node = root->get("scenario");
    if (node == nullptr)
        return tl::unexpected(fmt::format("{}: no [scenario] table", file.string()));
    for (const auto& [key, value] : *root)
        if (key.str() != "scenario")
            return tl::unexpected(fmt::format(
                "{}:{}:{}: {}: unknown key (a scenario file holds "
                "a [scenario] table)",
                file.string(), key.source().begin.line, key.source().begin.column, key.str()));
    return load_scenario_table(*node, file.string(), "scenario");
}

tl::expected<ScenarioConfig, std::string> reload_scenario(const ScenarioConfig& old) {
    if (old.plc.empty()) {
        auto root = ScenarioLoader::parse_file(old.reload_file);
        if (!root) return tl::unexpected(root.error());
        const auto* node = root->get("scenario");
        if (node == nullptr)
            return tl::unexpected(fmt::format("{}: no [scenario] table", old.reload_file.string()));
        auto config = load_scenario_table(*node, old.reload_file.string(), "scenario");
        if (config) config->reload_file = old.reload_file;
        return config;
    }
    auto root = ScenarioLoader::parse_file(old.reload_file);
    if (!root) return tl::unexpected(root.error());
    const auto* plcs = root->get_as<toml::array>("plc");
    for (std::size_t i = 0; plcs != nullptr && i < plcs->size(); ++i) {
        const auto* t = (*plcs)[i].as_table();
        if (t == nullptr) continue;
        const auto* name = t->get_as<std::string>("name");
        if (name == nullptr || name->get() != old.plc) continue;
        const auto* node = t->get("scenario");
        if (node == nullptr) break;
        auto config = load_scenario_table(*node, old.reload_file.string(),
                                          fmt::format("plc[{}].scenario", i));
        if (config) config->plc = old.plc;
        return config;
    }
    return tl::unexpected(fmt::format("{}: the [[plc]] named {} has no scenario table any more",
                                      old.reload_file.string(), old.plc));
}

tl::expected<std::unique_ptr<scenario::Scenario>, std::string> compile_scenario(
    const ScenarioConfig& config, plc::Plc& plc) {
    auto s = scenario::Scenario::compile(config.def, plc);
    if (s) return std::move(*s);
    const auto& e = s.error();
    const std::string& file = e.pos.source < config.sources.size() ? config.sources[e.pos.source]
                                                                   : config.reload_file.string();
    if (e.pos.line == 0) return tl::unexpected(fmt::format("{}: scenario: {}", file, e.message));
    return tl::unexpected(fmt::format("{}:{}:{}: {}", file, e.pos.line, e.pos.column, e.message));
}

}  // namespace fins::cli::finsd
