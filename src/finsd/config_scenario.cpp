// The [scenario] loader (contract in config_scenario.hpp): the table's own keys and the
// files it names here, its entries in config_scenario_entries.cpp.
#include "finsd/config_scenario.hpp"

#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "config/text_file.hpp"
#include "finsd/config_scenario_loader.hpp"
#include "finsd/config_values.hpp"
#include "plc/plc.hpp"
#include "scenario/scenario.hpp"

namespace fins::finsd {

using Unexpected = tl::unexpected<std::string>;

tl::expected<void, std::string> ScenarioLoader::table(const toml::node& node,
                                                      const std::string& path, bool allow_file) {
    const auto* t = node.as_table();
    if (t == nullptr) return fail(node, path, "must be a table");
    // `file` first: what the table adds comes after what the file holds.
    if (const auto* file = t->get("file")) {
        if (!allow_file) return fail(*file, path + ".file", "a scenario file cannot name another");
        const auto* name = file->as_string();
        if (name == nullptr || name->get().empty())
            return fail(*file, path + ".file", "must be a file name");
        std::filesystem::path p = name->get();
        if (p.is_relative()) p = std::filesystem::path(source_).parent_path() / p;
        auto root = parse_file(p);
        if (!root) return tl::unexpected(root.error());
        const auto* inner = root->get("scenario");
        if (inner == nullptr)
            return fail(*file, path + ".file",
                        fmt::format("{} has no [scenario] table", p.string()));
        ScenarioLoader nested(out_, p.string());
        if (auto r = nested.table(*inner, "scenario", false); !r) return r;
    }
    using config::Entry;
    using config::Type;
    using Done = tl::expected<void, std::string>;
    auto& def = out_.def;
    // [[scenario.signal]], [[scenario.link]], ...: an array of tables, each read by `read`.
    const auto entries = [this](std::string_view name, auto read) -> config::Key {
        return {name, Type::any, [this, read](const Entry& e) -> Done {
                    const auto* list = e.node.as_array();
                    if (list == nullptr)
                        return e.fail(fmt::format("must be an array of tables ([[{}]])", e.path));
                    for (std::size_t i = 0; i < list->size(); ++i) {
                        const auto& item = (*list)[i];
                        const std::string ip = fmt::format("{}[{}]", e.path, i);
                        if (!item.is_table()) return fail(item, ip, "must be a table");
                        if (auto r = read(*item.as_table(), ip); !r) return r;
                    }
                    return {};
                }};
    };
    return config::read_table(
        *t, {source_, path},
        {{"file"},  // read above
         config::integer_key("seed", def.seed, 0, std::numeric_limits<std::int64_t>::max()),
         {"tick_ms", Type::integer,
          [&](const Entry& e) -> Done {
              auto n = e.integer(1, 3'600'000);
              if (!n) return tl::unexpected(n.error());
              def.tick_s = static_cast<double>(*n) / 1000.0;
              return {};
          }},
         {"time", Type::string,
          [&](const Entry& e) -> Done {
              if (e.text() != "real" && e.text() != "virtual")
                  return e.fail(fmt::format("'{}' is not real or virtual", e.text()));
              def.virtual_time = e.text() == "virtual";
              return {};
          }},
         {"compute", Type::string,
          [&](const Entry& e) -> Done {
              const std::string& s = e.text();
              if (s != "auto" && s != "io" && s != "thread")
                  return e.fail(fmt::format("'{}' is not auto, io or thread", s));
              out_.compute = s == "io"       ? ComputeOn::io_thread
                             : s == "thread" ? ComputeOn::scenario_thread
                                             : ComputeOn::automatic;
              return {};
          }},
         number_key("time_scale",
                    [&](const Entry& e, double d) -> Done {
                        if (!(d > 0 && d <= 1000))
                            return e.fail("must be above 0 and at most 1000");
                        def.time_scale = d;
                        return {};
                    }),
         entries("signal",
                 [this](const toml::table& e, const std::string& p) { return tag(e, p, false); }),
         entries("link",
                 [this](const toml::table& e, const std::string& p) { return tag(e, p, true); }),
         entries("input",
                 [this](const toml::table& e, const std::string& p) { return input(e, p); }),
         entries("event",
                 [this](const toml::table& e, const std::string& p) { return event(e, p); }),
         entries("loop",
                 [this](const toml::table& e, const std::string& p) { return loop_item(e, p); })});
}

namespace {

// The byte offset of (line, column) in `text`; toml++ counts columns in characters.
std::size_t offset_of(std::string_view text, std::size_t line, std::size_t column) {
    std::size_t at = 0;
    for (std::size_t l = 1; l < line && at < text.size(); ++l) {
        const auto nl = text.find('\n', at);
        if (nl == std::string_view::npos) return text.size();
        at = nl + 1;
    }
    for (std::size_t c = 1; c < column && at < text.size(); ++c) {
        ++at;
        while (at < text.size() && (static_cast<unsigned char>(text[at]) & 0xC0) == 0x80)
            ++at;
    }
    return at;
}

}  // namespace

std::string ScenarioLoader::read_text(std::string_view file) {
    auto text = config::read_text_file(std::filesystem::path(file));
    return text ? std::move(*text) : std::string();
}

std::string ScenarioLoader::raw(const toml::source_region& r) const {
    if (text_.empty() || r.begin.line == 0) return {};
    const std::size_t begin = offset_of(text_, r.begin.line, r.begin.column);
    if (begin >= text_.size()) return {};
    const char quote = text_[begin];
    if (quote != '"' && quote != '\'') return {};
    const std::string delimiter(text_.compare(begin, 3, std::string(3, quote)) == 0 ? 3 : 1, quote);
    // Up to the closing delimiter (a basic string's \" does not close it).
    for (std::size_t i = begin + delimiter.size(); i < text_.size(); ++i) {
        if (quote == '"' && text_[i] == '\\') {
            ++i;
            continue;
        }
        if (text_.compare(i, delimiter.size(), delimiter) == 0)
            return text_.substr(begin, i + delimiter.size() - begin);
        if (delimiter.size() == 1 && text_[i] == '\n') break;
    }
    return {};
}

tl::expected<toml::table, std::string> ScenarioLoader::parse_file(
    const std::filesystem::path& file) {
    const auto text = config::read_text_file(file);
    if (!text) return Unexpected(text.error());
    try {
        return toml::parse(*text, file.string());
    } catch (const toml::parse_error& e) {
        return Unexpected(fmt::format("{}:{}:{}: {}", file.string(), e.source().begin.line,
                                      e.source().begin.column, e.description()));
    }
}

tl::expected<ScenarioConfig, std::string> load_scenario_table(const toml::node& node,
                                                              std::string_view source,
                                                              const std::string& path) {
    ScenarioConfig config;
    config.reload_file = std::string(source);
    ScenarioLoader loader(config, source);
    if (auto r = loader.table(node, path, true); !r) return tl::unexpected(r.error());
    return config;
}

tl::expected<ScenarioConfig, std::string> load_scenario_file(const std::filesystem::path& file) {
    auto root = ScenarioLoader::parse_file(file);
    if (!root) return tl::unexpected(root.error());
    const auto* node = root->get("scenario");
    if (node == nullptr)
        return tl::unexpected(fmt::format("{}: no [scenario] table", file.string()));
    const std::string source = file.string();
    if (auto r = config::read_table(*root,
                                    {source,
                                     "",
                                     config::At::key,
                                     {},
                                     "unknown key (a scenario file holds a [scenario] table)"},
                                    {{"scenario"}});
        !r)
        return tl::unexpected(r.error());
    return load_scenario_table(*node, source, "scenario");
}

tl::expected<ScenarioConfig, std::string> load_scenario_text(std::string_view text,
                                                             std::string_view source) {
    toml::table root;
    try {
        root = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        return Unexpected(fmt::format("{}:{}:{}: {}", source, e.source().begin.line,
                                      e.source().begin.column, e.description()));
    }
    const auto* node = root.get("scenario");
    if (node == nullptr) return Unexpected(fmt::format("{}: no [scenario] table", source));
    if (auto r = config::read_table(
            root,
            {source, "", config::At::key, {}, "unknown key (a scenario holds a [scenario] table)"},
            {{"scenario"}});
        !r)
        return tl::unexpected(r.error());
    ScenarioConfig config;
    ScenarioLoader loader(config, source, text);
    if (auto r = loader.table(*node, "scenario", true); !r) return tl::unexpected(r.error());
    // Nothing to read again: reload answers that the scenario came from no file.
    return config;
}

void set_scenario_time(ScenarioConfig& config, bool virtual_time) {
    config.def.virtual_time = virtual_time;
    config.virtual_time = virtual_time;
}

namespace {

tl::expected<ScenarioConfig, std::string> read_again(const ScenarioConfig& old) {
    if (old.reload_file.empty())
        return Unexpected("the scenario was given as text, not a file: nothing to reload");
    if (old.plc.empty()) {
        auto root = ScenarioLoader::parse_file(old.reload_file);
        if (!root) return tl::unexpected(root.error());
        const auto* node = root->get("scenario");
        if (node == nullptr)
            return tl::unexpected(fmt::format("{}: no [scenario] table", old.reload_file.string()));
        auto config = load_scenario_table(*node, old.reload_file.string(), "scenario");
        if (config) config->reload_file = old.reload_file;
        return config;
    }
    auto root = ScenarioLoader::parse_file(old.reload_file);
    if (!root) return tl::unexpected(root.error());
    const auto* plcs = root->get_as<toml::array>("plc");
    for (std::size_t i = 0; plcs != nullptr && i < plcs->size(); ++i) {
        const auto* t = (*plcs)[i].as_table();
        if (t == nullptr) continue;
        const auto* name = t->get_as<std::string>("name");
        if (name == nullptr || name->get() != old.plc) continue;
        const auto* node = t->get("scenario");
        if (node == nullptr) break;
        auto config = load_scenario_table(*node, old.reload_file.string(),
                                          fmt::format("plc[{}].scenario", i));
        if (config) config->plc = old.plc;
        return config;
    }
    return tl::unexpected(fmt::format("{}: the [[plc]] named {} has no scenario table any more",
                                      old.reload_file.string(), old.plc));
}

}  // namespace

tl::expected<ScenarioConfig, std::string> reload_scenario(const ScenarioConfig& old) {
    auto fresh = read_again(old);
    if (fresh && old.virtual_time) set_scenario_time(*fresh, *old.virtual_time);
    return fresh;
}

tl::expected<std::unique_ptr<scenario::Scenario>, std::string> compile_scenario(
    const ScenarioConfig& config, plc::Plc& plc) {
    auto s = scenario::Scenario::compile(config.def, plc);
    if (s) return std::move(*s);
    const auto& e = s.error();
    const std::string& file = e.pos.source < config.sources.size() ? config.sources[e.pos.source]
                                                                   : config.reload_file.string();
    if (e.pos.line == 0) return tl::unexpected(fmt::format("{}: scenario: {}", file, e.message));
    return tl::unexpected(fmt::format("{}:{}:{}: {}", file, e.pos.line, e.pos.column, e.message));
}

}  // namespace fins::finsd
