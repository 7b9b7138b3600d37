// The TOML loader of finsd's configuration file (config.hpp). Each key is read with
// its type and range checked; the first problem ends the load with a message naming
// the file position and the dotted key.
#include "finsd/config.hpp"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "fins/values.hpp"
#include "finsd/config_plant.hpp"
#include "finsd/config_values.hpp"

namespace fins::finsd {

namespace {

class Loader {
  public:
    Loader(std::string_view source, Settings& settings) : source_(source), s_(settings) {}

    Expected<void> load(const toml::table& root) {
        for (const auto& [key_ptr, node_ptr] : in_file_order(root)) {
            const toml::key& key = *key_ptr;
            const toml::node& node = *node_ptr;
            const std::string k(key.str());
            Expected<void> r;
            if (k == "profile")
                r = text(key, node, k, s_.profile);
            else if (k == "mode")
                r = mode(key, node);
            else if (k == "data_dir")
                r = path(key, node, k, s_.data_dir);
            else if (k == "control")
                r = path(key, node, k, s_.control_socket);
            else if (k == "log_level")
                r = text(key, node, k, s_.log_level);
            else if (k == "network")
                r = section(key, node, k, &Loader::network);
            else if (k == "protection")
                r = section(key, node, k, &Loader::protection);
            else if (k == "memory")
                r = section(key, node, k, &Loader::memory);
            else if (k == "storage")
                r = section(key, node, k, &Loader::storage);
            else if (k == "inject")
                r = section(key, node, k, &Loader::inject);
            else if (k == "files")
                r = section(key, node, k, &Loader::files);
            else if (k == "serial")
                r = load_serial_table(node, source_, s_.serial);
            else if (k == "plc")
                r = load_plant(key, node, source_, s_);
            else if (k == "remote")
                r = load_remotes(key, node, source_, s_);
            else if (k == "schedule")
                r = load_schedule(key, node, source_, s_);
            else if (k == "http")
                r = load_http_table(node, source_, s_.http);

            else if (k == "scenario")
                r = scenario(node);
            else
                r = fail(key, k, "unknown key");
            if (!r) return r;
        }
        return {};
    }

  private:
    using Handler = Expected<void> (Loader::*)(const toml::key&, const toml::node&,
                                               const std::string&);

    tl::unexpected<Error> fail(const toml::key& key, std::string_view path,
                               std::string_view message) const {
        return fail_at(key.source(), path, message);
    }
    tl::unexpected<Error> fail_at(const toml::source_region& where, std::string_view path,
                                  std::string_view message) const {
        return tl::unexpected<Error>(fmt::format("{}:{}:{}: {}: {}", source_, where.begin.line,
                                                 where.begin.column, path, message));
    }
    std::string position(const toml::key& key) const {
        return fmt::format("{}:{}:{}", source_, key.source().begin.line, key.source().begin.column);
    }

    Expected<void> section(const toml::key& key, const toml::node& node, const std::string& path,
                           Handler handler) {
        const auto* table = node.as_table();
        if (table == nullptr) return fail(key, path, "must be a table");
        for (const auto& [k, v] : in_file_order(*table)) {
            const std::string child = path + "." + std::string(k->str());
            if (auto r = (this->*handler)(*k, *v, child); !r) return r;
        }
        return {};
    }

    Expected<void> text(const toml::key& key, const toml::node& node, const std::string& path,
                        std::string& out) const {
        const auto* v = node.as_string();
        if (v == nullptr) return fail(key, path, "must be a string");
        out = v->get();
        return {};
    }
    Expected<void> path(const toml::key& key, const toml::node& node, const std::string& p,
                        std::optional<std::filesystem::path>& out) const {
        std::string value;
        if (auto r = text(key, node, p, value); !r) return r;
        if (value.empty()) return fail(key, p, "must not be empty");
        out = value;
        return {};
    }
    Expected<void> flag(const toml::key& key, const toml::node& node, const std::string& path,
                        bool& out) const {
        const auto* v = node.as_boolean();
        if (v == nullptr) return fail(key, path, "must be true or false");
        out = v->get();
        return {};
    }
    Expected<std::int64_t> integer(const toml::key& key, const toml::node& node,
                                   const std::string& path, std::int64_t lo,
                                   std::int64_t hi) const {
        const auto* v = node.as_integer();
        if (v == nullptr) return fail(key, path, "must be an integer");
        if (v->get() < lo || v->get() > hi)
            return fail(key, path, fmt::format("{} is not {}-{}", v->get(), lo, hi));
        return v->get();
    }

    Expected<void> scenario(const toml::node& node) {
        auto config = load_scenario_table(node, source_, "scenario");
        if (!config) return tl::unexpected(config.error());
        s_.scenario = std::move(*config);
        return {};
    }

    Expected<void> mode(const toml::key& key, const toml::node& node) {
        std::string value;
        if (auto r = text(key, node, "mode", value); !r) return r;
        const auto m = parse_mode(value);
        if (!m) return fail(key, "mode", fmt::format("'{}' is not program, monitor or run", value));
        s_.mode = *m;
        return {};
    }

    Expected<void> network(const toml::key& key, const toml::node& node, const std::string& p) {
        const std::string_view k = key.str();
        if (k == "bind") return text(key, node, p, s_.bind);
        if (k == "udp") return flag(key, node, p, s_.udp);
        if (k == "tcp") return flag(key, node, p, s_.tcp);
        std::int64_t lo = 0;
        std::int64_t hi = 0;
        if (k == "node")
            hi = 254;
        else if (k == "network")
            hi = 127;
        else if (k == "port")
            hi = 65535;
        else if (k == "max_connections") {
            lo = 1;
            hi = 254;
        } else if (k == "tcp_handshake_timeout" || k == "tcp_frame_timeout") {
            lo = 1;
            hi = 3600;
        } else if (k == "tcp_idle_timeout")
            hi = 86400;
        else if (k == "tcp_keepalive")
            hi = 7200;
        else if (k == "tcp_max_pending") {
            lo = 1;
            hi = 1024;
        } else
            return fail(key, p, "unknown key");
        const auto v = integer(key, node, p, lo, hi);
        if (!v) return tl::unexpected<Error>(v.error());
        if (k == "node") s_.node = static_cast<std::uint8_t>(*v);
        if (k == "network") s_.network = static_cast<std::uint8_t>(*v);
        if (k == "port") s_.port = static_cast<std::uint16_t>(*v);
        if (k == "max_connections") s_.max_connections = static_cast<std::size_t>(*v);
        if (k == "tcp_handshake_timeout") s_.tcp_handshake_timeout = static_cast<unsigned>(*v);
        if (k == "tcp_frame_timeout") s_.tcp_frame_timeout = static_cast<unsigned>(*v);
        if (k == "tcp_idle_timeout") s_.tcp_idle_timeout = static_cast<unsigned>(*v);
        if (k == "tcp_keepalive") s_.tcp_keepalive = static_cast<unsigned>(*v);
        if (k == "tcp_max_pending") s_.tcp_max_pending = static_cast<std::size_t>(*v);
        return {};
    }

    // [files] card = true/false, card_kbytes = 1-4194303, em_file_bank = 0-24,
    // cassette = true/false.
    Expected<void> files(const toml::key& key, const toml::node& node, const std::string& p) {
        const std::string_view k = key.str();
        if (k == "card") {
            bool inserted = true;
            if (auto r = flag(key, node, p, inserted); !r) return r;
            if (!inserted)
                s_.card_kbytes = 0;
            else if (s_.card_kbytes == 0u)
                s_.card_kbytes.reset();
            return {};
        }
        if (k == "card_kbytes") {
            const auto v = integer(key, node, p, 1, 4194303);
            if (!v) return tl::unexpected(v.error());
            if (s_.card_kbytes != 0u) s_.card_kbytes = static_cast<std::uint32_t>(*v);
            return {};
        }
        if (k == "cassette") {
            bool mounted = true;
            if (auto r = flag(key, node, p, mounted); !r) return r;
            s_.cassette = mounted;
            return {};
        }
        if (k == "em_file_bank") {
            const auto v = integer(key, node, p, 0, 24);
            if (!v) return tl::unexpected(v.error());
            s_.em_file_bank = static_cast<std::uint8_t>(*v);
            return {};
        }
        return fail(key, p, "unknown key");
    }

    Expected<void> protection(const toml::key& key, const toml::node& node, const std::string& p) {
        const std::string_view k = key.str();
        if (k == "um_read") return flag(key, node, p, s_.um_read_protection);
        if (k == "dip_write") return flag(key, node, p, s_.dip_write_protection);
        if (k == "password") {
            std::string value;
            if (auto r = text(key, node, p, value); !r) return r;
            // CJ2 CPU Units take 16 characters (CS/CJ 8); printable ASCII.
            const bool printable = std::all_of(value.begin(), value.end(),
                                               [](char c) { return c >= 0x20 && c < 0x7F; });
            if (value.empty() || value.size() > 16 || !printable)
                return fail(key, p, "must be 1-16 printable ASCII characters");
            s_.um_password = value;
            return {};
        }
        if (k == "network_write") {
            std::string value;
            if (auto r = text(key, node, p, value); !r) return r;
            const auto mode = parse_protection(value);
            if (!mode)
                return fail(
                    key, p,
                    fmt::format("'{}' is not off, all, listed or all-except-listed", value));
            s_.network_write_protection.mode = *mode;
            return {};
        }
        if (k != "nodes") return fail(key, p, "unknown key");
        const auto* list = node.as_array();
        if (list == nullptr) return fail(key, p, "must be an array of \"network.node\" strings");
        if (list->size() > plc::max_protection_nodes)
            return fail(key, p, fmt::format("more than {} nodes", plc::max_protection_nodes));
        s_.network_write_protection.nodes.clear();
        for (std::size_t i = 0; i < list->size(); ++i) {
            const auto* item = (*list)[i].as_string();
            const auto n = item != nullptr ? parse_node(item->get()) : std::nullopt;
            if (!n)
                return fail(key, fmt::format("{}[{}]", p, i),
                            "must be \"network.node\" (network 0-127, node 1-254 or *)");
            s_.network_write_protection.nodes.push_back(*n);
        }
        return {};
    }

    Expected<void> storage(const toml::key& key, const toml::node& node, const std::string& p) {
        if (key.str() != "durability") return fail(key, p, "unknown key");
        std::string value;
        if (auto r = text(key, node, p, value); !r) return r;
        const auto d = parse_durability(value);
        if (!d) return fail(key, p, fmt::format("'{}' is not process or power", value));
        s_.durability = *d;
        return {};
    }

    Expected<void> memory(const toml::key& key, const toml::node& node, const std::string&) {
        auto entry = memory_entry(key, node, source_, "memory");
        if (!entry) return tl::unexpected<Error>(entry.error());
        s_.memory.push_back(std::move(*entry));
        return {};
    }

    Expected<plc::FalInjection> fal(const toml::key& key, const toml::node& node,
                                    const std::string& p) const {
        const auto* t = node.as_table();
        if (t == nullptr) return fail(key, p, "must be { number = 1-511, message = \"...\" }");
        plc::FalInjection f;
        for (const auto& [key_ptr, node_ptr] : in_file_order(*t)) {
            const toml::key& k = *key_ptr;
            const toml::node& v = *node_ptr;
            const std::string child = p + "." + std::string(k.str());
            if (k.str() == "number") {
                const auto n = integer(k, v, child, 1, 511);
                if (!n) return tl::unexpected<Error>(n.error());
                f.number = static_cast<std::uint16_t>(*n);
            } else if (k.str() == "message") {
                if (auto r = text(k, v, child, f.message); !r) return tl::unexpected(r.error());
            } else {
                return fail(k, child, "unknown key");
            }
        }
        if (f.number == 0) return fail(key, p + ".number", "missing");
        return f;
    }

    Expected<void> inject(const toml::key& key, const toml::node& node, const std::string& p) {
        const std::string_view k = key.str();
        auto& in = s_.inject;
        if (k == "battery_error") return flag(key, node, p, in.battery_error);
        if (k == "fals") {
            const auto f = fal(key, node, p);
            if (!f) return tl::unexpected<Error>(f.error());
            in.fals = *f;
        } else if (k == "fal") {
            const auto* list = node.as_array();
            if (list == nullptr) return fail(key, p, "must be an array of { number, message }");
            in.fal.clear();
            for (std::size_t i = 0; i < list->size(); ++i) {
                const auto f = fal(key, (*list)[i], fmt::format("{}[{}]", p, i));
                if (!f) return tl::unexpected<Error>(f.error());
                in.fal.push_back(*f);
            }
        } else if (k == "messages") {
            const auto* t = node.as_table();
            if (t == nullptr) return fail(key, p, "must be a table { 0 = \"text\", ... }");
            for (const auto& [key_ptr, node_ptr] : in_file_order(*t)) {
                const toml::key& n = *key_ptr;
                const toml::node& v = *node_ptr;
                const std::string child = p + "." + std::string(n.str());
                const std::string_view digit = n.str();
                if (digit.size() != 1 || digit[0] < '0' || digit[0] > '7')
                    return fail(n, child, "message numbers are 0-7");
                std::string value;
                if (auto r = text(n, v, child, value); !r) return r;
                in.messages[static_cast<std::size_t>(digit[0] - '0')] = value;
            }
        } else if (k == "errors") {
            const auto* list = node.as_array();
            if (list == nullptr) return fail(key, p, "must be an array of error codes");
            in.errors.clear();
            for (std::size_t i = 0; i < list->size(); ++i) {
                const auto v = integer(key, (*list)[i], fmt::format("{}[{}]", p, i), 0, 0xFFFF);
                if (!v) return tl::unexpected<Error>(v.error());
                in.errors.push_back(static_cast<std::uint16_t>(*v));
            }
        } else {
            return fail(key, p, "unknown key");
        }
        // The injections' own rules (plc/injections.hpp): "fal[0].message: longer than
        // 16 characters" becomes "inject.fal[0].message: longer than 16 characters".
        if (const auto e = plc::validate(in); !e.empty()) {
            const auto colon = std::min(e.find(": "), e.size());
            // "inject." or "plc[N].inject.": the path up to this key.
            const std::string section = p.substr(0, p.rfind('.') + 1);
            return fail(key, section + e.substr(0, colon),
                        colon < e.size() ? std::string_view(e).substr(colon + 2) : "invalid");
        }
        return {};
    }

  public:
    // A [[plc]]'s own [protection], [inject], [storage] or [files] table.
    Expected<void> cpu_section(const toml::key& key, const toml::node& node, const std::string& p) {
        if (key.str() == "protection") return section(key, node, p, &Loader::protection);
        if (key.str() == "inject") return section(key, node, p, &Loader::inject);
        if (key.str() == "storage") return section(key, node, p, &Loader::storage);
        if (key.str() == "files") return section(key, node, p, &Loader::files);
        return fail(key, p, "unknown key");
    }

  private:
    std::string_view source_;
    Settings& s_;
};

}  // namespace

Expected<void> load_cpu_section(const toml::key& key, const toml::node& node,
                                std::string_view source, const std::string& path, Settings& cpu) {
    return Loader(source, cpu).cpu_section(key, node, path);
}

Expected<void> load_config_text(std::string_view text, std::string_view source,
                                Settings& settings) {
    toml::table root;
    try {
        root = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        return tl::unexpected<Error>(fmt::format("{}:{}:{}: {}", source, e.source().begin.line,
                                                 e.source().begin.column, e.description()));
    }
    Settings copy = settings;  // all or nothing
    if (auto r = Loader(source, copy).load(root); !r) return r;
    settings = std::move(copy);
    return {};
}

Expected<void> load_config_file(const std::filesystem::path& file, Settings& settings) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return tl::unexpected<Error>(fmt::format("{}: cannot read the file", file.string()));
    std::ostringstream text;
    text << in.rdbuf();
    return load_config_text(text.str(), file.string(), settings);
}

}  // namespace fins::finsd
