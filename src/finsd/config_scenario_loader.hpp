// The [scenario] table reader behind config_scenario.hpp: one ScenarioLoader per source
// file (a table naming a file reads it with a nested loader). Each key is read with its
// type and checked; keys that do not apply to a signal's kind are refused like unknown
// ones. Every error reads "FILE:LINE:COLUMN: PATH: message". Internal to finsd's config.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>
#include <tl/expected.hpp>

#include "config/schema.hpp"
#include "finsd/config_scenario.hpp"

namespace fins::finsd {

class ScenarioLoader {
    using Unexpected = tl::unexpected<std::string>;

  public:
    // `text`: the source's TOML text, for positions inside string values (Text::raw);
    // empty: read from the file `source` when there is one.
    ScenarioLoader(ScenarioConfig& out, std::string_view source, std::string_view text = {})
        : out_(out),
          source_(source),
          index_(static_cast<std::uint32_t>(out.sources.size())),
          text_(text.empty() ? read_text(source) : std::string(text)) {
        out_.sources.emplace_back(source);
    }

    // Reads the [scenario] table `node` at `path`; `allow_file`: it may name a file.
    tl::expected<void, std::string> table(const toml::node& node, const std::string& path,
                                          bool allow_file);

    static tl::expected<toml::table, std::string> parse_file(const std::filesystem::path& file);

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
        return scenario::Text{*s, pos(v.source()), raw(v.source())};
    }
    // The file's text of region `r` (a string value, quotes included); "" when unknown.
    [[nodiscard]] std::string raw(const toml::source_region& r) const;
    static std::string read_text(std::string_view file);
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

    // A key holding a finite number (an integer or a float), handed to `take`.
    using Take = std::function<tl::expected<void, std::string>(const config::Entry&, double)>;
    static config::Key number_key(std::string_view name, Take take) {
        return {
            name, config::Type::number,
            [take = std::move(take)](const config::Entry& e) -> tl::expected<void, std::string> {
                if (!std::isfinite(e.number())) return e.fail("must be a finite number");
                return take(e, e.number());
            }};
    }
    // A key holding a non-empty string, kept with its position for the scenario's messages.
    config::Key located_key(std::string_view name, scenario::Text& out,
                            bool required = false) const {
        return {name, config::Type::any,
                [this, &out](const config::Entry& e) -> tl::expected<void, std::string> {
                    auto s = located_text(e.node, e.path);
                    if (!s) return tl::unexpected(s.error());
                    out = *s;
                    return {};
                },
                required};
    }
    tl::expected<void, std::string> steps(const config::Entry& e, scenario::TagDef& d) const;

    // [[scenario.signal]] and [[scenario.link]] (config_scenario_entries.cpp).
    tl::expected<void, std::string> tag(const toml::table& t, const std::string& path,
                                        bool is_link);
    tl::expected<void, std::string> input(const toml::table& t, const std::string& path);
    tl::expected<void, std::string> event(const toml::table& t, const std::string& path);
    // [[scenario.loop]]: a Loop Control Board ITEM answered from memory.
    tl::expected<void, std::string> loop_item(const toml::table& t, const std::string& path);

    ScenarioConfig& out_;
    std::string source_;
    std::uint32_t index_;
    std::string text_;
};

}  // namespace fins::finsd
