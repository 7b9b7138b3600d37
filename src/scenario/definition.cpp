// Names of the scenario file's enumerations (contract in definition.hpp).
#include "scenario/definition.hpp"

#include <array>
#include <utility>

namespace fins::scenario {

namespace {

template <typename E, std::size_t N>
std::optional<E> find(const std::array<std::pair<std::string_view, E>, N>& table,
                      std::string_view name) {
    for (const auto& [text, value] : table)
        if (text == name) return value;
    return std::nullopt;
}
template <typename E, std::size_t N>
std::string_view name_of(const std::array<std::pair<std::string_view, E>, N>& table, E value) {
    for (const auto& [text, v] : table)
        if (v == value) return text;
    return "?";
}

constexpr std::array<std::pair<std::string_view, ValueType>, 10> value_types{{
    {"int16", ValueType::int16},
    {"uint16", ValueType::uint16},
    {"int32", ValueType::int32},
    {"uint32", ValueType::uint32},
    {"float", ValueType::float32},
    {"double", ValueType::float64},
    {"bcd", ValueType::bcd},
    {"bool", ValueType::boolean},
    {"float32", ValueType::float32},
    {"float64", ValueType::float64},
}};

constexpr std::array<std::pair<std::string_view, SignalKind>, 13> signal_kinds{{
    {"constant", SignalKind::constant},
    {"sine", SignalKind::sine},
    {"square", SignalKind::square},
    {"triangle", SignalKind::triangle},
    {"sawtooth", SignalKind::sawtooth},
    {"ramp", SignalKind::ramp},
    {"random_walk", SignalKind::random_walk},
    {"steps", SignalKind::steps},
    {"counter", SignalKind::counter},
    {"totaliser", SignalKind::totaliser},
    {"lag", SignalKind::lag},
    {"hysteresis", SignalKind::hysteresis},
    {"link", SignalKind::link},
}};

constexpr std::array<std::pair<std::string_view, FaultKind>, 14> fault_kinds{{
    {"stuck", FaultKind::stuck},
    {"drift", FaultKind::drift},
    {"spike", FaultKind::spike},
    {"set", FaultKind::set},
    {"noise", FaultKind::noise},
    {"fal", FaultKind::fal},
    {"fals", FaultKind::fals},
    {"battery", FaultKind::battery},
    {"mode", FaultKind::mode},
    {"end_code", FaultKind::end_code},
    {"offline", FaultKind::offline},
    {"latency", FaultKind::latency},
    {"drop", FaultKind::drop},
    {"clock_jump", FaultKind::clock_jump},
}};

}  // namespace

std::optional<ValueType> parse_value_type(std::string_view name) {
    return find(value_types, name);
}
std::string_view value_type_name(ValueType type) {
    return name_of(value_types, type);
}
unsigned value_words(ValueType type) {
    switch (type) {
        case ValueType::int16:
        case ValueType::uint16:
        case ValueType::bcd:
            return 1;
        case ValueType::int32:
        case ValueType::uint32:
        case ValueType::float32:
            return 2;
        case ValueType::float64:
            return 4;
        case ValueType::boolean:
            return 0;
    }
    return 1;
}

std::optional<SignalKind> parse_signal_kind(std::string_view name) {
    return find(signal_kinds, name);
}
std::string_view signal_kind_name(SignalKind kind) {
    return name_of(signal_kinds, kind);
}

std::optional<FaultKind> parse_fault_kind(std::string_view name) {
    return find(fault_kinds, name);
}
std::string_view fault_kind_name(FaultKind kind) {
    return name_of(fault_kinds, kind);
}
bool is_value_fault(FaultKind kind) {
    return kind <= FaultKind::noise;
}

}  // namespace fins::scenario
