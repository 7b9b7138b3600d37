// The fins-bridge TOML loader's class (config.hpp's parse_config), shared by the files
// that define its parts: config.cpp (the file, [bridge], [mqtt], [[plc]], groups) and
// config_tag.cpp (a tag: its address, type and bounds, checked against the table and the
// PLC model). A failure is thrown as a Failure with "file:line:col: message".
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "bridge/config.hpp"
#include "config/schema.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/node_address.hpp"
#include "plc/profile.hpp"

namespace fins::bridge::detail {

struct Failure {
    std::string message;
};

class Loader {
  public:
    explicit Loader(std::string source) : source_(std::move(source)) {}

    [[noreturn]] void fail(const toml::source_region& where, const std::string& message) const {
        throw Failure{
            fmt::format("{}:{}:{}: {}", source_, where.begin.line, where.begin.column, message)};
    }
    [[noreturn]] void fail(const toml::node& n, const std::string& message) const {
        fail(n.source(), message);
    }

    // Every key of `t` must be one of `known`; the first other one in the file is the error,
    // worded as every loader's (config/schema.hpp).
    void only(const toml::table& t, std::string_view where,
              std::initializer_list<std::string_view> known) const {
        const std::vector<config::Key> keys(known.begin(), known.end());
        if (auto r = config::read_table(t, {source_, "", config::At::value, where}, keys); !r)
            throw Failure{r.error()};
    }

    const toml::table& table(const toml::node& n, std::string_view what) const {
        const auto* t = n.as_table();
        if (t == nullptr) fail(n, fmt::format("{} must be a table", what));
        return *t;
    }

    std::optional<std::string> text(const toml::table& t, std::string_view key) const {
        const auto* n = t.get(key);
        if (n == nullptr) return std::nullopt;
        const auto* s = n->as_string();
        if (s == nullptr) fail(*n, fmt::format("{} must be a string", key));
        return s->get();
    }
    std::string text_or(const toml::table& t, std::string_view key, std::string fallback) const {
        auto v = text(t, key);
        return v ? *v : std::move(fallback);
    }
    std::string required_text(const toml::table& t, std::string_view key,
                              std::string_view where) const {
        auto v = text(t, key);
        if (!v) fail(t.source(), fmt::format("{} needs '{}'", where, key));
        return *v;
    }
    std::optional<std::int64_t> integer(const toml::table& t, std::string_view key, std::int64_t lo,
                                        std::int64_t hi) const {
        const auto* n = t.get(key);
        if (n == nullptr) return std::nullopt;
        const auto* i = n->as_integer();
        if (i == nullptr) fail(*n, fmt::format("{} must be an integer", key));
        if (i->get() < lo || i->get() > hi)
            fail(*n, fmt::format("{} must be {} to {}", key, lo, hi));
        return i->get();
    }
    std::optional<double> number(const toml::table& t, std::string_view key) const {
        const auto* n = t.get(key);
        if (n == nullptr) return std::nullopt;
        if (const auto* f = n->as_floating_point()) return f->get();
        if (const auto* i = n->as_integer()) return static_cast<double>(i->get());
        fail(*n, fmt::format("{} must be a number", key));
    }
    std::optional<bool> boolean(const toml::table& t, std::string_view key) const {
        const auto* n = t.get(key);
        if (n == nullptr) return std::nullopt;
        const auto* b = n->as_boolean();
        if (b == nullptr) fail(*n, fmt::format("{} must be true or false", key));
        return b->get();
    }
    std::string name(const toml::table& t, std::string_view where) const {
        auto v = required_text(t, "name", where);
        if (!valid_name(v))
            fail(*t.get("name"), fmt::format("name '{}' must be [A-Za-z0-9_-]+", v));
        return v;
    }
    template <class Rep, class Period>
    void duration(const toml::table& t, std::string_view key, std::int64_t lo, std::int64_t hi,
                  std::chrono::duration<Rep, Period>& out) const {
        if (auto v = integer(t, key, lo, hi)) out = std::chrono::duration<Rep, Period>(*v);
    }

    BridgeConfig load(const toml::table& root, const std::string& instance);

  private:
    void mqtt(const toml::table& t, Mqtt& m);
    Plc plc(const toml::table& t);
    NodeAddress node_address(const toml::node& n, const std::string& s) const;
    Group group(const toml::table& t, std::set<std::string>& tag_names);
    Tag tag(const toml::table& t);
    // Chooses how the tag is read and checks it against the table and the model.
    void resolve(const toml::node& at, Tag& tag) const;
    // The words [start, start+count) exist in this model and one segment of the table.
    void check_model(const toml::node& at, const Tag& tag, MemoryAddress start,
                     std::size_t count) const;
    std::size_t region_size(const MemoryAreaSegment& seg) const;

    std::string source_;
    const plc::Profile* profile_ = nullptr;
};

}  // namespace fins::bridge::detail
