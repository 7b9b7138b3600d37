// Declarative reading of one TOML table (schema.hpp).
#include "config/schema.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace fins::config {

std::string position(std::string_view source, const toml::source_region& where) {
    return fmt::format("{}:{}:{}", source, where.begin.line, where.begin.column);
}

Fail fail_at(std::string_view source, const toml::source_region& where, std::string_view path,
             std::string_view message) {
    if (path.empty()) return Fail(fmt::format("{}: {}", position(source, where), message));
    return Fail(fmt::format("{}: {}: {}", position(source, where), path, message));
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

namespace {

struct TypeInfo {
    Type type;
    std::string_view must_be;
    bool (*holds)(const toml::node&);
};

constexpr TypeInfo types[] = {
    {Type::any, "", [](const toml::node&) { return true; }},
    {Type::string, "must be a string", [](const toml::node& n) { return n.is_string(); }},
    {Type::integer, "must be an integer", [](const toml::node& n) { return n.is_integer(); }},
    {Type::number, "must be a number", [](const toml::node& n) { return n.is_number(); }},
    {Type::boolean, "must be true or false", [](const toml::node& n) { return n.is_boolean(); }},
    {Type::table, "must be a table", [](const toml::node& n) { return n.is_table(); }},
    {Type::array, "must be an array", [](const toml::node& n) { return n.is_array(); }},
};

const TypeInfo& info(Type type) {
    return types[static_cast<std::size_t>(type)];
}

}  // namespace

std::string_view must_be(Type type) {
    return info(type).must_be;
}

bool holds(const toml::node& node, Type type) {
    return info(type).holds(node);
}

Fail Entry::fail(std::string_view message) const {
    const auto& where = table.at == At::key ? key.source() : node.source();
    // fins-bridge's wording names the key before the complaint, without the path.
    if (!table.in.empty())
        return fail_at(table.source, where, "", fmt::format("{} {}", key.str(), message));
    return fail_at(table.source, where, path, message);
}

Expected<std::int64_t> Entry::integer(std::int64_t lo, std::int64_t hi) const {
    const std::int64_t v = node.as_integer()->get();
    if (v < lo || v > hi) return fail(fmt::format("{} is not {}-{}", v, lo, hi));
    return v;
}

Table Entry::child() const {
    return Table(table.source, path, table.at, table.in);
}

Expected<void> read_table(const toml::table& t, const Table& how, const std::vector<Key>& keys) {
    for (const auto& [key_ptr, node_ptr] : in_file_order(t)) {
        const std::string_view name = key_ptr->str();
        const Entry e{*key_ptr, *node_ptr,
                      how.path.empty() ? std::string(name) : how.path + "." + std::string(name),
                      how};
        const auto k = std::find_if(keys.begin(), keys.end(),
                                    [&](const Key& candidate) { return candidate.name == name; });
        if (k == keys.end()) {
            if (!how.in.empty())
                return fail_at(how.source, key_ptr->source(), "",
                               fmt::format("unknown key '{}' in {}", name, how.in));
            return fail_at(how.source, key_ptr->source(), e.path, how.unknown);
        }
        if (!holds(*node_ptr, k->type)) return e.fail(must_be(k->type));
        if (k->read)
            if (auto r = k->read(e); !r) return r;
    }
    for (const Key& k : keys) {
        if (!k.required || t.contains(k.name)) continue;
        if (!how.in.empty())
            return fail_at(how.source, t.source(), "",
                           fmt::format("{} needs '{}'", how.in, k.name));
        return fail_at(how.source, t.source(), how.path, fmt::format("{}: missing", k.name));
    }
    return {};
}

Expected<void> read_table(const Entry& e, const std::vector<Key>& keys) {
    return read_table(*e.node.as_table(), e.child(), keys);
}

Key text_key(std::string_view name, std::string& out) {
    return {name, Type::string, [&out](const Entry& e) -> Expected<void> {
                out = e.text();
                return {};
            }};
}

Key flag_key(std::string_view name, bool& out) {
    return {name, Type::boolean, [&out](const Entry& e) -> Expected<void> {
                out = e.flag();
                return {};
            }};
}

Key flag_key(std::string_view name, std::optional<bool>& out) {
    return {name, Type::boolean, [&out](const Entry& e) -> Expected<void> {
                out = e.flag();
                return {};
            }};
}

Key number_key(std::string_view name, double& out) {
    return {name, Type::number, [&out](const Entry& e) -> Expected<void> {
                out = e.number();
                return {};
            }};
}

}  // namespace fins::config
