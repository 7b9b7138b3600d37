// finsd's [memory] typed values (see config_values.hpp).
#include "finsd/config_values.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "fins/values.hpp"
#include "typed/value_format.hpp"

namespace fins::finsd {

namespace {

using WordList = std::vector<std::uint32_t>;
using Failure = tl::unexpected<TypedValueError>;
using typed::Format;

// The value formats of src/typed (fins --as, the web API, the bridge) that name words to
// store: not bits, nor hex (a way to print uint16).
bool storable(Format f) {
    return f != Format::bits && f != Format::hex;
}

// "int16, uint16, ... or string": the storable formats, from the one table.
const std::string& type_names() {
    static const std::string names = [] {
        std::vector<std::string_view> list;
        for (const Format f : typed::all_formats())
            if (storable(f)) list.push_back(typed::format_name(f));
        return fmt::format("{} or {}", fmt::join(list.begin(), list.end() - 1, ", "), list.back());
    }();
    return names;
}

// One value of format `f` appended to `out`; the message when it does not fit the format
// (its range is the table's: typed::json_to_words checks it).
std::optional<std::string> add_value(Format f, const toml::node& n, WordList& out) {
    if (f == Format::string) {
        const auto* text = n.as_string();
        if (text == nullptr) return "must be a string (two characters a word)";
        if (auto why = string_problem(text->get())) return *why;
        auto w = string_to_words(text->get());
        if (!w) return "must be a string (two characters a word)";
        out.insert(out.end(), w->begin(), w->end());
        return std::nullopt;
    }
    nlohmann::json value;
    if (typed::integer_range(f)) {
        const auto* i = n.as_integer();
        if (i == nullptr) return "must be an integer";
        value = i->get();
    } else if (const auto* real = n.as_floating_point()) {
        value = real->get();
    } else if (const auto* i = n.as_integer()) {
        value = i->get();
    } else {
        return "must be a number";
    }
    std::array<std::uint16_t, 4> words{};
    if (auto problem = typed::json_to_words(f, value, words)) return problem;
    const auto count = static_cast<std::ptrdiff_t>(typed::words_per_value(f));
    out.insert(out.end(), words.begin(), words.begin() + count);
    return std::nullopt;
}

}  // namespace

tl::expected<WordList, TypedValueError> typed_words(const toml::table& t) {
    if (t.size() != 1)
        return Failure({"", fmt::format("a typed value is one key: {}", type_names())});
    const auto first = t.begin();  // its pair refers into the iterator: keep it alive
    const std::string type(first->first.str());
    const toml::node& value = first->second;
    const auto format = typed::parse_format(type);
    if (!format || !storable(*format))
        return Failure({"", fmt::format("'{}' is not a value type: {}", type, type_names())});
    WordList out;
    if (const auto* list = value.as_array()) {
        if (list->empty()) return Failure({"." + type, "empty array"});
        for (const auto& n : *list)
            if (auto e = add_value(*format, n, out)) return Failure({"." + type, *e});
    } else if (auto e = add_value(*format, value, out)) {
        return Failure({"." + type, *e});
    }
    return out;
}

Expected<MemoryInit> memory_entry(const toml::key& key, const toml::node& node,
                                  std::string_view source, std::string_view prefix) {
    const std::string p = fmt::format("{}.\"{}\"", prefix, key.str());
    const auto fail = [&](const std::string& path, std::string_view message) {
        return tl::unexpected<Error>(fmt::format("{}:{}:{}: {}: {}", source,
                                                 key.source().begin.line, key.source().begin.column,
                                                 path, message));
    };
    MemoryInit entry;
    entry.key = std::string(key.str());
    entry.path = p;
    entry.where =
        fmt::format("{}:{}:{}", source, key.source().begin.line, key.source().begin.column);
    const auto address = parse_address(entry.key);
    if (!address) return fail(p, "not a PLC address (e.g. D100, H0, CIO10.13, E3_100)");
    entry.address = *address;
    const bool bit = address->bit.has_value();
    const bool wide = address->area == Area::index_register;
    const std::int64_t hi = bit ? 1 : wide ? 0xFFFFFFFF : 0xFFFF;
    const std::int64_t lo = bit ? 0 : wide ? std::numeric_limits<std::int32_t>::min() : -32768;
    const auto element = [&](const toml::node& n) -> Expected<std::uint32_t> {
        if (const auto* b = n.as_boolean(); b != nullptr && bit) return b->get() ? 1U : 0U;
        if (const auto* i = n.as_integer(); i != nullptr && i->get() >= lo && i->get() <= hi)
            return static_cast<std::uint32_t>(i->get());
        return fail(p, bit ? "bit values are true/false (or 0/1)"
                           : fmt::format("word values are integers {}..{}", lo, hi));
    };
    if (const auto* typed = node.as_table()) {
        if (bit || wide) return fail(p, "typed values ({ float = ... }) are for word addresses");
        auto words = typed_words(*typed);
        if (!words) return fail(p + words.error().path_suffix, words.error().message);
        entry.values = std::move(*words);
    } else if (const auto* list = node.as_array()) {
        if (list->empty()) return fail(p, "empty array");
        for (const auto& n : *list) {
            const auto v = element(n);
            if (!v) return tl::unexpected<Error>(v.error());
            entry.values.push_back(*v);
        }
    } else {
        const auto v = element(node);
        if (!v) return tl::unexpected<Error>(v.error());
        entry.values.push_back(*v);
    }
    return entry;
}

}  // namespace fins::finsd
