// Scenario::compile: checks a ScenarioDef against one CPU Unit (contract in scenario.hpp).
#include "scenario/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/core.h>

#include "fins/address.hpp"
#include "scenario/scenario_impl.hpp"

namespace fins::scenario {

namespace {

tl::unexpected<CompileError> error(SourcePos pos, std::string message) {
    return tl::unexpected(CompileError{pos, std::move(message)});
}

// Why IoMemory::locate refused an address, in words.
std::string located_error(std::string_view text, const plc::Plc& plc, std::error_code ec) {
    if (ec == EndCode::read_only) return fmt::format("{} is in a read-only area", text);
    if (ec == EndCode::address_range_exceeded)
        return fmt::format("{} runs past the end of its area on the {}", text, plc.profile().model);
    return fmt::format("the {} has no {}", plc.profile().model, text);
}

bool needs_input(SignalKind kind) {
    return kind == SignalKind::link || kind == SignalKind::counter ||
           kind == SignalKind::totaliser || kind == SignalKind::lag ||
           kind == SignalKind::hysteresis;
}

struct Compiler {
    Scenario::Impl& s;
    std::vector<Address> addresses;  // parallel to s.references

    tl::expected<std::uint32_t, std::string> locate(const Address& address, ValueType type,
                                                    std::string_view text, plc::Intent intent,
                                                    std::int32_t tag) {
        const bool bit_type = type == ValueType::boolean;
        Access access = Access::word;
        if (bit_type) {
            const bool flag_area = address.area == Area::timer || address.area == Area::counter ||
                                   address.area == Area::task_flag;
            if (!address.bit && !flag_area)
                return tl::unexpected(fmt::format(
                    "type \"bool\" needs a bit address ({}.00, or T/C for a completion flag)",
                    text));
            access = Access::bit;
        } else if (address.bit) {
            return tl::unexpected(fmt::format("{} is a bit: its type must be \"bool\", not \"{}\"",
                                              text, value_type_name(type)));
        }
        auto memory_address = to_memory_address(address, access);
        if (!memory_address)
            return tl::unexpected(fmt::format("{} cannot be accessed as {}: {}", text,
                                              value_type_name(type),
                                              memory_address.error().message()));
        const auto use = intent == plc::Intent::write ? use_write : use_read;
        auto range =
            s.plc->memory().locate(*memory_address, bit_type ? 1 : value_words(type), use, intent);
        if (!range) return tl::unexpected(located_error(text, *s.plc, range.error()));
        Reference reference;
        reference.range = *range;
        reference.type = type;
        reference.tag = tag;
        s.references.push_back(reference);
        addresses.push_back(address);
        return static_cast<std::uint32_t>(s.references.size() - 1);
    }

    // Overlap of the words (or bits) two references cover.
    static bool overlaps(const Reference& a, const Reference& b) {
        if (a.range.region != b.range.region || a.range.bank != b.range.bank) return false;
        const auto bit_kind = [](const plc::ElementRange& r) {
            return r.kind == ElementKind::bit || r.kind == ElementKind::bit_forced;
        };
        const bool a_bit = bit_kind(a.range), b_bit = bit_kind(b.range);
        if (a.range.kind != b.range.kind && !(a_bit || b_bit)) return false;  // flags vs words
        const std::uint32_t a_end = a.range.index + (a_bit ? 1 : a.range.count);
        const std::uint32_t b_end = b.range.index + (b_bit ? 1 : b.range.count);
        if (a.range.index >= b_end || b.range.index >= a_end) return false;
        if (a_bit && b_bit) return a.range.bit == b.range.bit;
        return true;
    }

    std::optional<std::uint32_t> resolve(const Address& address, std::string& message) {
        for (std::size_t i = 0; i < addresses.size(); ++i)
            if (addresses[i] == address) return static_cast<std::uint32_t>(i);
        const bool flag = !address.bit && (address.area == Area::task_flag);
        const auto type = address.bit || flag ? ValueType::boolean : ValueType::uint16;
        auto r = locate(address, type, format_address(address), plc::Intent::read, -1);
        if (!r) {
            message = r.error();
            return std::nullopt;
        }
        return *r;
    }

    tl::expected<std::optional<Expression>, CompileError> expression(const Text& text) {
        if (text.text.empty()) return std::optional<Expression>{};
        ExpressionError e;
        auto parsed = Expression::parse(
            text.text, [this](const Address& a, std::string& m) { return resolve(a, m); }, e);
        if (!parsed) return error(text.position(e.line, e.column), e.message);
        return parsed;
    }
};

}  // namespace

Scenario::Scenario(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Scenario::~Scenario() = default;

tl::expected<std::unique_ptr<Scenario>, CompileError> Scenario::compile(ScenarioDef definition,
                                                                        plc::Plc& plc) {
    auto impl = std::make_unique<Impl>();
    Impl& s = *impl;
    s.def = std::move(definition);
    s.plc = &plc;
    s.random.reseed(s.def.seed);
    const ScenarioDef& def = s.def;
    if (!(def.tick_s >= 0.001 && def.tick_s <= 3600))
        return error({}, fmt::format("tick_ms {} is not 1-3600000", def.tick_s * 1000));
    if (!(def.time_scale > 0 && def.time_scale <= 1000))
        return error({},
                     fmt::format("time_scale {} is not above 0 and at most 1000", def.time_scale));
    if (def.tags.size() > max_tags)
        return error({}, fmt::format("{} tags: at most {}", def.tags.size(), max_tags));
    if (def.events.size() > max_events)
        return error({}, fmt::format("{} events: at most {}", def.events.size(), max_events));

    Compiler c{s, {}};
    // Tags first: their references are the ones expressions find by address.
    s.tags.resize(def.tags.size());
    s.cold.resize(def.tags.size());
    for (std::size_t i = 0; i < def.tags.size(); ++i) {
        const TagDef& t = def.tags[i];
        auto address = parse_address(t.address.text);
        if (!address) return error(t.address.pos, address_error(t.address.text, address.error()));
        auto r = c.locate(*address, t.type, t.address.text, plc::Intent::write,
                          static_cast<std::int32_t>(i));
        if (!r) return error(t.address.pos, r.error());
        for (std::size_t j = 0; j < i; ++j)
            if (Compiler::overlaps(s.references[*r], s.references[s.tags[j].reference]))
                return error(t.address.pos,
                             fmt::format("{} overlaps {} ({}), written by the entry at line {}",
                                         t.address.text, def.tags[j].address.text,
                                         value_type_name(def.tags[j].type), def.tags[j].pos.line));
        s.cold[i].def = &t;
        s.tags[i].reference = *r;
        TagState& p = s.tags[i];
        p.kind = t.kind;
        p.repeat = t.repeat;
        switch (t.kind) {
            case SignalKind::constant:
                p.value = t.value;
                break;
            case SignalKind::sine:
            case SignalKind::square:
            case SignalKind::triangle:
            case SignalKind::sawtooth:
            case SignalKind::ramp:
                p.min = t.min;
                p.max = t.max;
                p.period_s = t.period_s;
                p.phase_s = t.phase_s;
                p.duty = t.duty;
                break;
            case SignalKind::random_walk:
                p.min = t.min;
                p.max = t.max;
                p.step = t.step;
                p.adopts = true;
                break;
            case SignalKind::counter:
                p.min = t.min;
                p.max = t.max;
                p.rate = t.rate;
                p.adopts = true;
                break;
            case SignalKind::totaliser:
                p.adopts = true;
                break;
            case SignalKind::lag:
                p.gain = 1 - std::exp(-def.tick_s / t.tau_s);
                p.noise = t.noise;
                p.adopts = true;
                break;
            case SignalKind::hysteresis:
                p.on_above = t.on_above;
                p.off_below = t.off_below;
                break;
            default:
                break;
        }
        if (t.kind == SignalKind::steps) {
            if (t.steps.empty())
                return error(t.pos, "kind = \"steps\" needs steps = [[t, value], ...]");
            for (std::size_t k = 1; k < t.steps.size(); ++k)
                if (t.steps[k].first < t.steps[k - 1].first)
                    return error(t.pos, "steps must be in ascending time order");
        }
        if ((t.kind == SignalKind::sine || t.kind == SignalKind::square ||
             t.kind == SignalKind::triangle || t.kind == SignalKind::sawtooth ||
             t.kind == SignalKind::ramp) &&
            !(t.period_s > 0))
            return error(t.pos, "period_s must be above 0");
        if (t.kind == SignalKind::lag && !(t.tau_s > 0))
            return error(t.pos, "tau_s must be above 0");
        if (t.kind == SignalKind::random_walk && t.max < t.min)
            return error(t.pos, "max is below min");
        if (t.delay_s < 0 || t.delay_s > max_delay_s)
            return error(t.pos, fmt::format("delay_s {} is not 0-{}", t.delay_s, max_delay_s));
        const auto samples = static_cast<std::size_t>(std::llround(t.delay_s / def.tick_s));
        if (samples > max_delay_samples)
            return error(t.pos, fmt::format("delay_s {} is {} ticks: at most {}", t.delay_s,
                                            samples, max_delay_samples));
        s.cold[i].delay.assign(samples, std::nan(""));
        s.tags[i].has_delay = samples > 0;
        if (s.tags[i].adopts)
            s.tags[i].state =
                t.initial.value_or(t.kind == SignalKind::random_walk ? (t.min + t.max) / 2 : 0.0);
    }
    for (const auto& in : def.inputs) {
        auto address = parse_address(in.address.text);
        if (!address) return error(in.address.pos, address_error(in.address.text, address.error()));
        for (const auto& known : c.addresses)
            if (known == *address)
                return error(in.address.pos,
                             fmt::format("{} is already a tag or an input", in.address.text));
        auto r = c.locate(*address, in.type, in.address.text, plc::Intent::read, -1);
        if (!r) return error(in.address.pos, r.error());
    }
    // The tags' expressions, until their programs are copied into s.code.
    std::vector<std::optional<Expression>> inputs(def.tags.size()), whens(def.tags.size());
    for (std::size_t i = 0; i < def.tags.size(); ++i) {
        const TagDef& t = def.tags[i];
        if (needs_input(t.kind) && t.input.text.empty())
            return error(t.pos, fmt::format("kind = \"{}\" needs {}", signal_kind_name(t.kind),
                                            t.kind == SignalKind::link  ? "expr"
                                            : t.kind == SignalKind::lag ? "setpoint"
                                                                        : "input"));
        auto input = c.expression(t.input);
        if (!input) return tl::unexpected(input.error());
        auto when = c.expression(t.when);
        if (!when) return tl::unexpected(when.error());
        inputs[i] = std::move(*input);
        whens[i] = std::move(*when);
    }

    // Dependency order: depth-first in file order, a tag after the tags it reads.
    // A tag reading itself reads its previous value (not a dependency).
    std::vector<std::uint8_t> mark(s.tags.size(), 0);  // 0 new, 1 on the path, 2 done
    std::vector<std::uint32_t> path;
    std::optional<CompileError> cycle;
    auto visit = [&](auto&& self, std::uint32_t i) -> void {
        if (cycle || mark[i] == 2) return;
        mark[i] = 1;
        path.push_back(i);
        for (const auto* e : {&inputs[i], &whens[i]}) {
            if (!*e) continue;
            for (auto ref : (*e)->references()) {
                const auto dep = s.references[ref].tag;
                if (dep < 0 || static_cast<std::uint32_t>(dep) == i) continue;
                const auto d = static_cast<std::uint32_t>(dep);
                if (mark[d] == 1) {
                    std::string chain;
                    auto from = std::find(path.begin(), path.end(), d);
                    for (auto it = from; it != path.end(); ++it)
                        chain += def.tags[*it].address.text + " -> ";
                    chain += def.tags[d].address.text;
                    cycle = CompileError{def.tags[d].pos, "the links form a cycle: " + chain};
                    return;
                }
                self(self, d);
                if (cycle) return;
            }
        }
        path.pop_back();
        mark[i] = 2;
        s.order.push_back(i);
    };
    for (std::uint32_t i = 0; i < s.tags.size(); ++i)
        visit(visit, i);
    if (cycle) return tl::unexpected(*cycle);
    for (const auto i : s.order) {
        auto place = [&s](const std::optional<Expression>& e, ProgramRef& where) {
            if (!e) return;
            where.at = static_cast<std::uint32_t>(s.code.size());
            where.size = static_cast<std::uint32_t>(e->program().size());
            s.code.insert(s.code.end(), e->program().begin(), e->program().end());
        };
        place(whens[i], s.cold[i].when);
        place(inputs[i], s.tags[i].input);
        s.tags[i].has_when = s.cold[i].when.size != 0;
    }
    for (auto& reference : s.references)
        s.bind_direct(reference);
    s.build_image();
    s.bind_words();

    s.events.resize(def.events.size());
    for (std::size_t i = 0; i < def.events.size(); ++i) {
        const EventDef& e = def.events[i];
        EventState& es = s.events[i];
        es.def = &e;
        es.name = e.name.empty() ? fmt::format("event-{}", i + 1) : e.name;
        for (std::size_t j = 0; j < i; ++j)
            if (s.events[j].name == es.name)
                return error(e.pos, fmt::format("a second event named \"{}\"", es.name));
        if (!e.at_s && !e.every_s) return error(e.pos, "an event needs at_s or every_s");
        if (e.every_s && !(*e.every_s > 0)) return error(e.pos, "every_s must be above 0");
        if (e.at_s && *e.at_s < 0) return error(e.pos, "at_s must not be negative");
        if (!(e.duration_s >= 0)) return error(e.pos, "duration_s must not be negative");
        es.next_start = e.at_s ? *e.at_s : *e.every_s;
        if (is_value_fault(e.fault)) {
            if (e.address.text.empty())
                return error(e.pos, fmt::format("fault = \"{}\" needs the address of a tag",
                                                fault_kind_name(e.fault)));
            auto address = parse_address(e.address.text);
            if (!address)
                return error(e.address.pos, fmt::format("\"{}\" is not an address: {}",
                                                        e.address.text, address.error().message()));
            for (std::size_t t = 0; t < s.tags.size() && es.tag < 0; ++t)
                if (c.addresses[s.tags[t].reference] == *address)
                    es.tag = static_cast<std::int32_t>(t);
            if (es.tag < 0)
                return error(e.address.pos,
                             fmt::format("{} is not a tag of this scenario (no signal or link "
                                         "writes it)",
                                         e.address.text));
            s.cold[static_cast<std::size_t>(es.tag)].faults.push_back(
                static_cast<std::uint32_t>(i));
            s.tags[static_cast<std::size_t>(es.tag)].has_faults = true;
        }
        switch (e.fault) {
            case FaultKind::fal:
            case FaultKind::fals:
                if (e.number < 1 || e.number > 511)
                    return error(e.pos, fmt::format("number {} is not 1-511", e.number));
                if (e.message.size() > 16)
                    return error(e.pos, "message is longer than 16 characters");
                break;
            case FaultKind::end_code: {
                auto address = parse_address(e.address.text);
                if (!address)
                    return error(e.address.pos.line ? e.address.pos : e.pos,
                                 "fault = \"end_code\" needs the address of the area");
                auto code = to_memory_address(*address, Access::word);
                if (!code) return error(e.address.pos, code.error().message());
                const auto* segment = find_segment(code->area_code, code->word);
                if (segment == nullptr)
                    return error(e.address.pos,
                                 fmt::format("{} is not in an I/O memory area", e.address.text));
                es.region = segment->region;
                es.em_bank = segment->em_bank;
                if (e.end_code == 0) return error(e.pos, "end_code must not be 0000");
                break;
            }
            case FaultKind::drop:
                if (!(e.value >= 0 && e.value <= 1))
                    return error(e.pos, fmt::format("value {} is not a fraction 0-1", e.value));
                break;
            case FaultKind::latency:
                if (!(e.value >= 0 && e.value <= 60000))
                    return error(e.pos, fmt::format("value {} ms is not 0-60000", e.value));
                break;
            default:
                break;
        }
    }
    // Loop Control Board ITEMs answered from memory, set last (only a scenario that
    // compiled replaces the running one's).
    std::vector<plc::LoopControl::ItemSource> sources;
    for (const auto& l : def.loop_items) {
        if (!plc.loop_control().present())
            return error(l.pos, fmt::format("the {} has no Loop Control Board (02 40): use a "
                                            "profile with one (cs1h-lcb)",
                                            plc.profile().model));
        const auto* block = l.block >= 0 && l.block <= 0xFFFF
                                ? plc::LoopControl::find_block(static_cast<std::uint16_t>(l.block))
                                : nullptr;
        if (block == nullptr)
            return error(l.pos,
                         fmt::format("block {} is not a function block of the board", l.block));
        const auto value = l.item >= 0 && l.item <= 0xFFFF
                               ? plc::LoopControl::read(*block, static_cast<std::uint16_t>(l.item))
                               : std::nullopt;
        if (!value)
            return error(l.pos, fmt::format("block {} ({}) has no readable ITEM {}", l.block,
                                            block->name, l.item));
        auto address = parse_address(l.address.text);
        if (!address)
            return error(l.address.pos, fmt::format("\"{}\" is not an address: {}", l.address.text,
                                                    address.error().message()));
        const auto type = value->length == 4 ? ValueType::uint32 : ValueType::uint16;
        auto r = c.locate(*address, type, l.address.text, plc::Intent::read, -1);
        if (!r) return error(l.address.pos, r.error());
        s.bind_direct(s.references[*r]);
        if (s.references[*r].memory == nullptr)
            return error(l.address.pos, fmt::format("{} is not in a word area (CIO, W, H, A, D, E)",
                                                    l.address.text));
        sources.push_back(
            {block->address, static_cast<std::uint16_t>(l.item), s.references[*r].memory});
    }
    if (!sources.empty()) plc.loop_control().set_sources(&s, std::move(sources));
    return std::unique_ptr<Scenario>(new Scenario(std::move(impl)));
}

Scenario::Impl::~Impl() {
    // A battery event holding the battery low ends with its scenario (a reload).
    if (plc != nullptr && std::any_of(events.begin(), events.end(), [](const EventState& e) {
            return e.holding && e.def->fault == FaultKind::battery;
        }))
        plc->errors().set_battery_cause(plc::ErrorState::battery_cause_scenario, false, host_now);
    if (plc != nullptr && !def.loop_items.empty()) plc->loop_control().clear_sources(this);
}

const ScenarioDef& Scenario::definition() const noexcept {
    return impl_->def;
}
double Scenario::time() const noexcept {
    return static_cast<double>(impl_->tick_count) * impl_->def.tick_s;
}
std::uint64_t Scenario::ticks() const noexcept {
    return impl_->tick_count;
}
const TransportFaults& Scenario::transport() const noexcept {
    return impl_->transport;
}

Status Scenario::status() const {
    Status st;
    st.time_s = time();
    st.ticks = impl_->tick_count;
    st.writes = impl_->writes;
    st.skipped_writes = impl_->skipped;
    st.tags = impl_->tags.size();
    for (const auto& e : impl_->events)
        st.events.push_back(
            {e.name, std::string(fault_kind_name(e.def->fault)), e.active, e.next_start});
    return st;
}

}  // namespace fins::scenario
