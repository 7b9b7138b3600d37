// The [[plc]] loader's class (config_plant.hpp's load_plant), shared by the files that
// define its parts: config_plant.cpp (the CPU Unit tables, repeat) and
// config_plant_ethernet.cpp (the Ethernet units, their IP tables, relay entries).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "config/schema.hpp"
#include "finsd/config.hpp"

namespace fins::finsd::detail {

class PlantLoader {
  public:
    explicit PlantLoader(std::string_view source) : source_(source) {}

    // The array of [[plc]] tables at `node` onto settings.plant.
    Expected<void> load(const toml::node& node, const toml::source_region& where,
                        Settings& settings);

  private:
    Expected<void> load_repeated(const toml::table& t, const toml::node& repeat,
                                 const std::string& path, Settings& settings);
    Expected<std::pair<int, int>> span_of(const toml::node& v, const std::string& path, int lo,
                                          int hi) const;
    Expected<void> load_cpu(const toml::table& t, const std::string& path,
                            server::PlantCpuConfig& cpu, Settings::PlantCpuSettings& extra);
    static Expected<void> check_serial(const std::string& path, const server::PlantCpuConfig& cpu,
                                       const Settings::PlantCpuSettings& extra);
    Expected<void> load_port(const toml::table& t, const std::string& path,
                             server::PlantPortConfig& port);
    Expected<void> load_ip_entry(const toml::table& t, const std::string& path,
                                 server::PlantPortConfig& port);
    Expected<void> load_relay(const toml::table& t, const std::string& path,
                              server::PlantCpuConfig& cpu);
    Expected<void> cpu_options(const config::Entry& e, Settings::PlantCpuSettings& extra);
    Expected<void> remotes(const config::Entry& e, const std::string& path,
                           server::PlantCpuConfig& cpu, Settings::PlantCpuSettings& extra);

    // The placeholders of the CPU Unit a repeated [[plc]] is being loaded for.
    struct Substitution {
        int network;
        int node;
        std::size_t index;
    };
    std::string substituted(std::string s) const {
        if (!substitution_) return s;
        const auto replace = [&s](std::string_view name, const std::string& value) {
            for (auto at = s.find(name); at != std::string::npos; at = s.find(name, at)) {
                s.replace(at, name.size(), value);
                at += value.size();
            }
        };
        replace("{network}", std::to_string(substitution_->network));
        replace("{node}", std::to_string(substitution_->node));
        replace("{index}", std::to_string(substitution_->index));
        return s;
    }
    std::optional<Substitution> substitution_;

    tl::unexpected<Error> fail(const toml::source_region& where, std::string_view path,
                               std::string_view message) const {
        return config::fail_at(source_, where, path, message);
    }

    // A string key, its {network}, {node} and {index} substituted.
    config::Key text_into(std::string_view name, std::string& out) const {
        return {name, config::Type::string, [this, &out](const config::Entry& e) -> Expected<void> {
                    out = substituted(e.text());
                    return {};
                }};
    }
    template <class F>
    Expected<void> tables(const toml::node& v, const std::string& path, F&& each) const {
        const auto* array = v.as_array();
        if (array == nullptr) return fail(v.source(), path, "must be an array of tables");
        for (std::size_t i = 0; i < array->size(); ++i) {
            const auto* t = (*array)[i].as_table();
            const std::string child = fmt::format("{}[{}]", path, i);
            if (t == nullptr) return fail((*array)[i].source(), child, "must be a table");
            if (auto r = each(*t, child); !r) return r;
        }
        return {};
    }

    std::string_view source_;
};

}  // namespace fins::finsd::detail
