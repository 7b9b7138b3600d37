#include "typed/value_format.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>
#include <limits>
#include <span>

#include <fmt/format.h>

#include "fins/values.hpp"

namespace fins::typed {

namespace {

struct FormatRow {
    Format format;
    std::string_view name;
    std::size_t words;
};

constexpr FormatRow formats[] = {
    {Format::int16, "int16", 1},   {Format::uint16, "uint16", 1}, {Format::int32, "int32", 2},
    {Format::uint32, "uint32", 2}, {Format::float32, "float", 2}, {Format::float64, "double", 4},
    {Format::bcd, "bcd", 1},       {Format::bcd32, "bcd32", 2},   {Format::string, "string", 1},
    {Format::bits, "bits", 0},     {Format::hex, "hex", 1},
};

// The Format column of `formats`, for all_formats().
constexpr auto format_order = [] {
    std::array<Format, std::size(formats)> out{};
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = formats[i].format;
    return out;
}();

// Decimal or 0x hex, with one optional sign: "--5", "+-5" and "0x-5" are refused
// (std::from_chars takes a '-' of its own, which would make "--5" read as 5).
template <class T>
std::optional<T> parse_integer(std::string_view s) {
    int base = 10;
    bool negative = false;
    if (!s.empty() && (s[0] == '-' || s[0] == '+')) {
        negative = s[0] == '-';
        s.remove_prefix(1);
    }
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
        base = 16;
        s.remove_prefix(2);
    }
    if (s.empty() || s[0] == '-' || s[0] == '+') return std::nullopt;
    long long v = 0;
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
    if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
    if (negative) v = -v;
    if (v < static_cast<long long>(std::numeric_limits<T>::min()) ||
        v > static_cast<long long>(std::numeric_limits<T>::max()))
        return std::nullopt;
    return static_cast<T>(v);
}

// A decimal number ("1.5", "-2e3", "inf", "nan"), or why not. A finite number too large
// for the format, or nonzero but too small to be anything but 0, is refused rather than
// stored as infinity or 0 (std::from_chars already refuses one out of double's range).
std::variant<double, std::string> parse_real(std::string_view s, Format f) {
    const auto name = format_name(f);
    const auto bad = [&] { return fmt::format("'{}' is not a valid {} value", s, name); };
    if (s.empty() || s[0] == '+') return bad();
    double v = 0;
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (end != s.data() + s.size()) return bad();
    if (ec == std::errc::result_out_of_range)
        return fmt::format("'{}' is out of range for {}", s, name);
    if (ec != std::errc{}) return bad();
    if (f == Format::float32 && std::isfinite(v)) {
        if (std::abs(v) > std::numeric_limits<float>::max())
            return fmt::format("'{}' is out of range for float (at most {:g} either side of 0)", s,
                               std::numeric_limits<float>::max());
        if (v != 0 && static_cast<float>(v) == 0)
            return fmt::format("'{}' is too small for float (it would be 0)", s);
    }
    return v;
}

template <class F>
Printed number(F v) {
    return {fmt::format("{}", v), nlohmann::json(v)};
}

Printed real(double v) {
    // JSON has no NaN/Infinity: print those as strings so the document stays valid.
    if (!std::isfinite(v)) return {fmt::format("{}", v), nlohmann::json(fmt::format("{}", v))};
    return {fmt::format("{}", v), nlohmann::json(v)};
}

// A JSON value in an error message: never throws, whatever bytes a string holds.
std::string dump(const nlohmann::json& j) {
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

template <class Array>
void append(std::vector<std::uint16_t>& out, const Array& words) {
    out.insert(out.end(), words.begin(), words.end());
}

}  // namespace

std::span<const Format> all_formats() noexcept {
    return format_order;
}

std::optional<Format> parse_format(std::string_view name) {
    for (const auto& f : formats)
        if (f.name == name) return f.format;
    if (name == "float32") return Format::float32;
    if (name == "float64") return Format::float64;
    if (name == "ascii") return Format::string;
    if (name == "bool") return Format::bits;
    return std::nullopt;
}

std::string_view format_name(Format f) {
    for (const auto& row : formats)
        if (row.format == f) return row.name;
    return "?";
}

std::size_t words_per_value(Format f) {
    for (const auto& row : formats)
        if (row.format == f) return row.words;
    return 1;
}

std::optional<bool> parse_bit(std::string_view s) {
    if (s == "1" || s == "on" || s == "ON" || s == "true") return true;
    if (s == "0" || s == "off" || s == "OFF" || s == "false") return false;
    return std::nullopt;
}

Result<std::vector<Printed>> print_words(Format f, const std::vector<std::uint16_t>& words) {
    std::vector<Printed> out;
    if (f == Format::string) {
        // words_to_string gives valid UTF-8 (one character a byte, Latin-1), so the dump
        // cannot throw; replace stays as the last line of defence.
        nlohmann::json j = words_to_string(words);
        out.push_back({j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), j});
        return out;
    }
    // Bits take one word a value here (the bit as word 0, as in append_json): with the
    // table's 0 words per value the loop would never advance.
    const std::size_t step = f == Format::bits ? 1 : words_per_value(f);
    for (std::size_t i = 0; i + step <= words.size(); i += step) {
        const Words w{words.data() + i, step};
        switch (f) {
            case Format::int16:
                out.push_back(number(*words_to_int16(w)));
                break;
            case Format::uint16:
                out.push_back(number(*words_to_uint16(w)));
                break;
            case Format::int32:
                out.push_back(number(*words_to_int32(w)));
                break;
            case Format::uint32:
                out.push_back(number(*words_to_uint32(w)));
                break;
            case Format::float32:
                out.push_back(real(static_cast<double>(*words_to_float(w))));
                break;
            case Format::float64:
                out.push_back(real(*words_to_double(w)));
                break;
            case Format::hex: {
                auto t = fmt::format("0x{:04X}", w[0]);
                out.push_back({t, nlohmann::json(t)});
                break;
            }
            case Format::bcd: {
                auto v = words_to_bcd16(w);
                if (!v) return Unexpected(v.error());
                out.push_back(number(*v));
                break;
            }
            case Format::bcd32: {
                auto v = words_to_bcd32(w);
                if (!v) return Unexpected(v.error());
                out.push_back(number(*v));
                break;
            }
            case Format::bits:
                out.push_back({w[0] != 0 ? "1" : "0", nlohmann::json(w[0] != 0)});
                break;
            case Format::string:
                break;
        }
    }
    return out;
}

std::variant<std::vector<std::uint16_t>, ParseError> parse_words(
    Format f, const std::vector<std::string>& values) {
    std::vector<std::uint16_t> out;
    if (f == Format::string) {
        std::string joined;
        for (std::size_t i = 0; i < values.size(); ++i)
            joined += (i ? " " : "") + values[i];
        if (auto why = string_problem(joined))
            return ParseError{fmt::format("cannot write that text as a string: {}", *why)};
        auto w = string_to_words(joined);
        if (!w) return ParseError{"cannot write that text as a string"};
        return *w;
    }
    for (const auto& v : values) {
        auto bad = [&] {
            return ParseError{fmt::format("'{}' is not a valid {} value", v, format_name(f))};
        };
        switch (f) {
            case Format::int16: {
                auto x = parse_integer<std::int16_t>(v);
                if (!x) return bad();
                append(out, int16_to_words(*x));
                break;
            }
            case Format::uint16:
            case Format::hex: {
                auto x = parse_integer<std::uint16_t>(v);
                if (!x) return bad();
                append(out, uint16_to_words(*x));
                break;
            }
            case Format::int32: {
                auto x = parse_integer<std::int32_t>(v);
                if (!x) return bad();
                append(out, int32_to_words(*x));
                break;
            }
            case Format::uint32: {
                auto x = parse_integer<std::uint32_t>(v);
                if (!x) return bad();
                append(out, uint32_to_words(*x));
                break;
            }
            case Format::float32:
            case Format::float64: {
                auto x = parse_real(v, f);
                if (auto* why = std::get_if<std::string>(&x)) return ParseError{std::move(*why)};
                const double d = std::get<double>(x);
                if (f == Format::float32)
                    append(out, float_to_words(static_cast<float>(d)));
                else
                    append(out, double_to_words(d));
                break;
            }
            case Format::bcd: {
                auto x = parse_integer<std::uint16_t>(v);
                auto w = x ? bcd16_to_words(*x) : Result<std::array<std::uint16_t, 1>>{};
                if (!x || !w) return ParseError{fmt::format("'{}' is not BCD 0-9999", v)};
                append(out, *w);
                break;
            }
            case Format::bcd32: {
                auto x = parse_integer<std::uint32_t>(v);
                auto w = x ? bcd32_to_words(*x) : Result<std::array<std::uint16_t, 2>>{};
                if (!x || !w) return ParseError{fmt::format("'{}' is not BCD 0-99999999", v)};
                append(out, *w);
                break;
            }
            case Format::bits: {
                auto b = parse_bit(v);
                if (!b) return ParseError{fmt::format("'{}' is not a bit (0/1/on/off)", v)};
                out.push_back(*b ? 1 : 0);
                break;
            }
            case Format::string:
                break;
        }
    }
    return out;
}

std::optional<std::pair<double, double>> integer_range(Format f) noexcept {
    switch (f) {
        case Format::int16:
            return std::pair{-32768.0, 32767.0};
        case Format::uint16:
        case Format::hex:
            return std::pair{0.0, 65535.0};
        case Format::int32:
            return std::pair{-2147483648.0, 2147483647.0};
        case Format::uint32:
            return std::pair{0.0, 4294967295.0};
        case Format::bcd:
            return std::pair{0.0, 9999.0};
        case Format::bcd32:
            return std::pair{0.0, 99999999.0};
        case Format::bits:
            return std::pair{0.0, 1.0};
        case Format::float32:
        case Format::float64:
        case Format::string:
            break;
    }
    return std::nullopt;
}

std::optional<double> to_number(Format f, Words w) noexcept {
    const auto as = [](auto r) -> std::optional<double> {
        if (!r) return std::nullopt;
        return static_cast<double>(*r);
    };
    switch (f) {
        case Format::bits:
            return w[0] != 0 ? 1.0 : 0.0;
        case Format::int16:
            return as(words_to_int16(w.first(1)));
        case Format::uint16:
        case Format::hex:
            return w[0];
        case Format::int32:
            return as(words_to_int32(w.first(2)));
        case Format::uint32:
            return as(words_to_uint32(w.first(2)));
        case Format::float32:
            return as(words_to_float(w.first(2)));
        case Format::float64:
            return as(words_to_double(w.first(4)));
        case Format::bcd:
            return as(words_to_bcd16(w.first(1)));
        case Format::bcd32:
            return as(words_to_bcd32(w.first(2)));
        case Format::string:
            break;
    }
    return std::nullopt;
}

void append_json(std::string& out, Format f, Words w) {
    auto it = std::back_inserter(out);
    switch (f) {
        case Format::bits:
            out += w[0] != 0 ? "true" : "false";
            return;
        case Format::int16:
            fmt::format_to(it, "{}", static_cast<std::int16_t>(w[0]));
            return;
        case Format::uint16:
        case Format::hex:
            fmt::format_to(it, "{}", w[0]);
            return;
        case Format::int32:
            fmt::format_to(it, "{}", words_to_int32(w.first(2)).value_or(0));
            return;
        case Format::uint32:
            fmt::format_to(it, "{}", words_to_uint32(w.first(2)).value_or(0));
            return;
        case Format::float32: {
            const float v = words_to_float(w.first(2)).value_or(0);
            // JSON has no NaN or infinity.
            if (std::isfinite(v))
                fmt::format_to(it, "{}", v);
            else
                out += "null";
            return;
        }
        case Format::float64: {
            const double v = words_to_double(w.first(4)).value_or(0);
            if (std::isfinite(v))
                fmt::format_to(it, "{}", v);
            else
                out += "null";
            return;
        }
        case Format::bcd:
        case Format::bcd32: {
            const auto v = to_number(f, w);
            if (v)
                fmt::format_to(it, "{}", static_cast<std::uint32_t>(*v));
            else
                out += "null";
            return;
        }
        case Format::string:
            out += "null";
            return;
    }
}

std::optional<std::string> json_to_words(Format f, const nlohmann::json& value,
                                         std::array<std::uint16_t, 4>& words) {
    const auto name = f == Format::bits ? std::string_view("bool") : format_name(f);
    const auto put = [&words](const auto& w) { std::copy(w.begin(), w.end(), words.begin()); };
    if (f == Format::string) return "a string is not one fixed-size value";
    if (f == Format::bits) {
        if (value.is_boolean())
            words[0] = value.get<bool>() ? 1 : 0;
        else if (value.is_number_integer() &&
                 (value.get<std::int64_t>() == 0 || value.get<std::int64_t>() == 1))
            words[0] = static_cast<std::uint16_t>(value.get<std::int64_t>());
        else
            return std::string("bool needs true, false, 0 or 1");
        return std::nullopt;
    }
    if (!value.is_number()) return fmt::format("{} needs a JSON number", name);
    const double d = value.get<double>();
    if (auto r = integer_range(f)) {
        if (!value.is_number_integer())
            return fmt::format("{} needs an integer, not {}", name, dump(value));
        if (d < r->first || d > r->second)
            return fmt::format("{} is out of range for {} ({} to {})", dump(value), name, r->first,
                               r->second);
    } else if (!std::isfinite(d)) {
        // Not from JSON text (it has no infinity), but from a Sparkplug double metric.
        return fmt::format("the number is out of range for {}", name);
    } else if (f == Format::float32 && std::abs(d) > std::numeric_limits<float>::max()) {
        return fmt::format("{} is out of range for float", dump(value));
    } else if (f == Format::float32 && d != 0 && static_cast<float>(d) == 0) {
        return fmt::format("{} is too small for float (it would be 0)", dump(value));
    }
    switch (f) {
        case Format::int16:
            put(int16_to_words(value.get<std::int16_t>()));
            break;
        case Format::uint16:
        case Format::hex:
            put(uint16_to_words(value.get<std::uint16_t>()));
            break;
        case Format::int32:
            put(int32_to_words(value.get<std::int32_t>()));
            break;
        case Format::uint32:
            put(uint32_to_words(value.get<std::uint32_t>()));
            break;
        case Format::float32:
            put(float_to_words(static_cast<float>(d)));
            break;
        case Format::float64:
            put(double_to_words(d));
            break;
        case Format::bcd:
            put(*bcd16_to_words(value.get<std::uint16_t>()));
            break;
        case Format::bcd32:
            put(*bcd32_to_words(value.get<std::uint32_t>()));
            break;
        case Format::string:
        case Format::bits:
            break;
    }
    return std::nullopt;
}

}  // namespace fins::typed
