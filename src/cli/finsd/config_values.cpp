// finsd's [memory] typed values (see config_values.hpp).
#include "cli/finsd/config_values.hpp"

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <limits>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "fins/values.hpp"

namespace fins::cli::finsd {

namespace {

using WordList = std::vector<std::uint32_t>;
using Failure = tl::unexpected<TypedValueError>;

constexpr std::string_view types =
    "int16, uint16, int32, uint32, float, double, bcd, bcd32 or string";

// One value of `type` appended to `out`; the message when it does not fit the type.
std::optional<std::string> add_value(const std::string& type, const toml::node& n, WordList& out) {
    const auto add = [&out](const auto& words) {
        out.insert(out.end(), words.begin(), words.end());
    };
    if (type == "string") {
        const auto* text = n.as_string();
        auto w = text ? string_to_words(text->get()) : Result<std::vector<std::uint16_t>>{};
        if (!text || !w) return "must be a string (two characters a word)";
        add(*w);
        return std::nullopt;
    }
    if (type == "float" || type == "double") {
        std::optional<double> v;
        if (const auto* f = n.as_floating_point()) v = f->get();
        if (const auto* i = n.as_integer()) v = static_cast<double>(i->get());
        if (!v) return "must be a number";
        if (type == "float")
            add(float_to_words(static_cast<float>(*v)));
        else
            add(double_to_words(*v));
        return std::nullopt;
    }
    const auto* i = n.as_integer();
    if (i == nullptr) return "must be an integer";
    const std::int64_t v = i->get();
    const auto in = [v](std::int64_t lo, std::int64_t hi) { return v >= lo && v <= hi; };
    if (type == "int16" && in(-32768, 32767))
        add(int16_to_words(static_cast<std::int16_t>(v)));
    else if (type == "uint16" && in(0, 0xFFFF))
        add(uint16_to_words(static_cast<std::uint16_t>(v)));
    else if (type == "int32" &&
             in(std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()))
        add(int32_to_words(static_cast<std::int32_t>(v)));
    else if (type == "uint32" && in(0, 0xFFFFFFFF))
        add(uint32_to_words(static_cast<std::uint32_t>(v)));
    else if (type == "bcd" && in(0, 9999))
        add(*bcd16_to_words(static_cast<std::uint16_t>(v)));
    else if (type == "bcd32" && in(0, 99999999))
        add(*bcd32_to_words(static_cast<std::uint32_t>(v)));
    else
        return fmt::format("{} out of range for {}", v, type);
    return std::nullopt;
}

}  // namespace

tl::expected<WordList, TypedValueError> typed_words(const toml::table& t) {
    if (t.size() != 1) return Failure({"", fmt::format("a typed value is one key: {}", types)});
    const auto first = t.begin();  // its pair refers into the iterator: keep it alive
    const std::string type(first->first.str());
    const toml::node& value = first->second;
    static constexpr std::string_view known[] = {"int16",  "uint16", "int32", "uint32", "float",
                                                 "double", "bcd",    "bcd32", "string"};
    if (std::find(std::begin(known), std::end(known), type) == std::end(known))
        return Failure({"", fmt::format("'{}' is not a value type: {}", type, types)});
    WordList out;
    if (const auto* list = value.as_array()) {
        if (list->empty()) return Failure({"." + type, "empty array"});
        for (const auto& n : *list)
            if (auto e = add_value(type, n, out)) return Failure({"." + type, *e});
    } else if (auto e = add_value(type, value, out)) {
        return Failure({"." + type, *e});
    }
    return out;
}

std::vector<std::pair<const toml::key*, const toml::node*>> in_file_order(const toml::table& t) {
    std::vector<std::pair<const toml::key*, const toml::node*>> entries;
    for (auto&& [k, v] : t)
        entries.emplace_back(&k, &v);
    std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
        const auto& x = a.first->source().begin;
        const auto& y = b.first->source().begin;
        return x.line != y.line ? x.line < y.line : x.column < y.column;
    });
    return entries;
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

}  // namespace fins::cli::finsd
