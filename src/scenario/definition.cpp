// Names of the scenario file's enumerations (contract in definition.hpp).
#include "scenario/definition.hpp"

#include <array>
#include <cctype>
#include <utility>

#include <fmt/core.h>

#include "fins/address.hpp"
#include "fins/error.hpp"

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

namespace {

// Bytes of the UTF-8 character whose first byte is `lead` (1 for a stray byte).
std::size_t utf8_length(unsigned char lead) {
    if (lead >= 0xF0 && lead < 0xF8) return 4;
    if (lead >= 0xE0) return lead < 0xF0 ? 3 : 1;
    if (lead >= 0xC0) return 2;
    return 1;
}

}  // namespace

SourcePos Text::position(std::uint32_t line, std::uint32_t column) const {
    if (pos.line == 0) return {line, column, pos.source};
    if (raw.empty()) {
        if (line == 1) return {pos.line, pos.column + column, pos.source};
        return {pos.line + line - 1, column, pos.source};
    }
    // Walk the value as written and as decoded side by side: (raw_line, raw_column) is
    // where raw[i] is in the file, (line_now, column_now) the decoded character it gives.
    const bool literal = raw.front() == '\'';
    const bool multi = raw.rfind("\"\"\"", 0) == 0 || raw.rfind("'''", 0) == 0;
    const std::size_t quote = multi ? 3 : 1;
    const std::size_t end = raw.size() >= 2 * quote ? raw.size() - quote : raw.size();
    std::size_t i = std::min(quote, raw.size());
    std::uint32_t raw_line = pos.line, raw_column = pos.column + static_cast<std::uint32_t>(i);
    const auto next_line = [&] {
        ++raw_line;
        raw_column = 1;
    };
    // A line break right after the opening """ is not part of the value.
    if (multi && i < end && raw[i] == '\r' && i + 1 < end && raw[i + 1] == '\n') {
        i += 2;
        next_line();
    } else if (multi && i < end && raw[i] == '\n') {
        ++i;
        next_line();
    }
    std::uint32_t line_now = 1, column_now = 1;
    while (i < end) {
        const auto c = static_cast<unsigned char>(raw[i]);
        if (!literal && c == '\\' && i + 1 < end) {
            const char n = raw[i + 1];
            if (multi && (n == ' ' || n == '\t' || n == '\r' || n == '\n')) {
                // A line-ending backslash: it and the white space after it give nothing.
                ++i;
                ++raw_column;
                while (i < end &&
                       (raw[i] == ' ' || raw[i] == '\t' || raw[i] == '\r' || raw[i] == '\n')) {
                    if (raw[i] == '\n')
                        next_line();
                    else
                        ++raw_column;
                    ++i;
                }
                continue;
            }
        }
        if (line_now == line && column_now == column) return {raw_line, raw_column, pos.source};
        if (!literal && c == '\\' && i + 1 < end) {
            const char n = raw[i + 1];
            const std::size_t length = n == 'u' ? 6 : n == 'U' ? 10 : 2;
            i += length;
            raw_column += static_cast<std::uint32_t>(length);
            if (n == 'n') {
                ++line_now;
                column_now = 1;
            } else {
                ++column_now;
            }
            continue;
        }
        if (c == '\n' || (c == '\r' && i + 1 < end && raw[i + 1] == '\n')) {
            i += c == '\r' ? 2 : 1;
            next_line();
            ++line_now;
            column_now = 1;
            continue;
        }
        i += utf8_length(c);
        ++raw_column;
        ++column_now;
    }
    return {raw_line, raw_column, pos.source};  // past the end: the closing quote
}

std::string address_error(std::string_view text, const std::error_code& error) {
    if (error == AddressError::word_out_of_range) {
        // The area's prefix: what comes before the word's digits (after E<bank>_).
        const auto underscore = text.find('_');
        std::size_t digits = underscore == std::string_view::npos ? 0 : underscore + 1;
        while (digits < text.size() && std::isdigit(static_cast<unsigned char>(text[digits])) == 0)
            ++digits;
        const std::string prefix(text.substr(0, digits));
        if (auto area = parse_address(prefix + "0"))
            return fmt::format("{} is out of range: {}0-{}{}", text, prefix, prefix,
                               max_word(area->area));
    }
    if (error == AddressError::bit_out_of_range)
        return fmt::format("{} is out of range: bits 00-15", text);
    return fmt::format("\"{}\" is not an address: {}", text, error.message());
}

}  // namespace fins::scenario
