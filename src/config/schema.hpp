// Declarative reading of one TOML table, for finsd's and fins-bridge's configuration
// loaders. A loader lists a table's keys once: the name, the TOML type its value must have,
// whether the key is required, and what to do with the value. read_table() walks the table
// in file order and answers an unknown key, a value of the wrong type and a missing key
// with the same message for every loader, as one line "FILE:LINE:COLUMN: message":
//   plant.toml:3:1: plc[0].colour: unknown key
//   bad.toml:2:1: network.node: must be an integer
//   plant.toml:1:1: plc[0]: name: missing
// or, in fins-bridge's wording (Table::in set to "[mqtt]"):
//   t.toml:3:1: unknown key 'hots' in [mqtt]
//   t.toml:4:8: port must be an integer
// The first problem ends the walk; nothing after it is read.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <toml++/toml.h>
#include <tl/expected.hpp>

namespace fins::config {

using Fail = tl::unexpected<std::string>;
template <class T = void>
using Expected = tl::expected<T, std::string>;

// "FILE:LINE:COLUMN" of `where`.
std::string position(std::string_view source, const toml::source_region& where);

// "FILE:LINE:COLUMN: PATH: MESSAGE" ("FILE:LINE:COLUMN: MESSAGE" when `path` is empty).
Fail fail_at(std::string_view source, const toml::source_region& where, std::string_view path,
             std::string_view message);

// A table's entries in file order (toml::table iterates in key order): the first problem
// reported is the first in the file, and entries are applied in the order written.
std::vector<std::pair<const toml::key*, const toml::node*>> in_file_order(const toml::table& t);

// What a key's value must be; `any` leaves the check to the key's reader.
enum class Type { any, string, integer, number, boolean, table, array };

// "must be a string", "must be an integer", "must be a number" (an integer or a float),
// "must be true or false", "must be a table", "must be an array"; "" for any.
std::string_view must_be(Type type);
bool holds(const toml::node& node, Type type);

// Where a value's problems point: the value itself, or the key naming it.
enum class At { value, key };

// How a table is read: the file, the table's dotted path and the wording of messages.
struct Table {
    Table(std::string_view file, std::string table_path, At where = At::value,
          std::string_view named = {}, std::string_view unknown_key = "unknown key")
        : source(file), path(std::move(table_path)), at(where), in(named), unknown(unknown_key) {}

    std::string_view source;  // the file name messages start with
    std::string path;         // "plc[0].ethernet[0]"; "" for the file's root table
    At at;
    // Empty: finsd's wording, "PATH.KEY: unknown key", "PATH.KEY: must be ...",
    // "PATH: KEY: missing". Else fins-bridge's, naming the table: "unknown key 'KEY' in
    // [mqtt]", "KEY must be ...", "[mqtt] needs 'KEY'".
    std::string_view in;
    // The complaint about an unknown key in finsd's wording.
    std::string_view unknown;
};

// One key of a table being read, handed to that key's reader.
struct Entry {
    const toml::key& key;
    const toml::node& node;
    std::string path;  // the table's path + "." + the key ("KEY" at the root)
    const Table& table;

    // "FILE:LINE:COLUMN: PATH: MESSAGE" at the value (or its key, Table::at).
    [[nodiscard]] Fail fail(std::string_view message) const;
    // The value, its type already checked by read_table.
    [[nodiscard]] const std::string& text() const { return node.as_string()->get(); }
    [[nodiscard]] bool flag() const { return node.as_boolean()->get(); }
    [[nodiscard]] double number() const { return *node.value<double>(); }
    // An integer within lo-hi, or "N is not LO-HI".
    [[nodiscard]] Expected<std::int64_t> integer(std::int64_t lo, std::int64_t hi) const;
    // How a table at this entry is read: the same file and wording, this entry's path.
    [[nodiscard]] Table child() const;
};

using Reader = std::function<Expected<void>(const Entry&)>;

struct Key {
    Key(std::string_view key_name, Type key_type = Type::any, Reader reader = {},
        bool is_required = false)
        : name(key_name), type(key_type), read(std::move(reader)), required(is_required) {}

    std::string_view name;
    Type type;
    Reader read;  // empty: the key is accepted here and read elsewhere
    bool required;
};

// Each key of `t` read by the one of `keys` with its name, in file order; then each
// required key that is absent is the error (in the order `keys` lists them).
Expected<void> read_table(const toml::table& t, const Table& how, const std::vector<Key>& keys);
// The entry's value as a table (Type::table checked by the caller's key), read with `keys`.
Expected<void> read_table(const Entry& e, const std::vector<Key>& keys);

// Keys that store their value as it is.
Key text_key(std::string_view name, std::string& out);
Key flag_key(std::string_view name, bool& out);
Key flag_key(std::string_view name, std::optional<bool>& out);
Key number_key(std::string_view name, double& out);
template <class T>
Key integer_key(std::string_view name, T& out, std::int64_t lo, std::int64_t hi) {
    return {name, Type::integer, [&out, lo, hi](const Entry& e) -> Expected<void> {
                const auto v = e.integer(lo, hi);
                if (!v) return Fail(v.error());
                out = static_cast<T>(*v);
                return {};
            }};
}

template <class T>
Key integer_key(std::string_view name, std::optional<T>& out, std::int64_t lo, std::int64_t hi) {
    return {name, Type::integer, [&out, lo, hi](const Entry& e) -> Expected<void> {
                const auto v = e.integer(lo, hi);
                if (!v) return Fail(v.error());
                out = static_cast<T>(*v);
                return {};
            }};
}

}  // namespace fins::config
