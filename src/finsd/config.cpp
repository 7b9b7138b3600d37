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

#include "config/schema.hpp"
#include "config/text_file.hpp"
#include "fins/values.hpp"
#include "finsd/config_plant.hpp"
#include "finsd/config_values.hpp"

namespace fins::finsd {

namespace {

using config::At;
using config::Entry;
using config::Key;
using config::Type;
using Fail = tl::unexpected<Error>;

class Loader {
  public:
    Loader(std::string_view source, Settings& settings) : source_(source), s_(settings) {}

    // Every problem at its key (the line names the key; the value may span lines).
    Expected<void> load(const toml::table& root) {
        return config::read_table(
            root, {source_, "", At::key},
            {config::text_key("profile", s_.profile),
             {"mode", Type::string, [this](const Entry& e) { return mode(e); }},
             path_key("data_dir", s_.data_dir),
             path_key("control", s_.control_socket),
             config::text_key("log_level", s_.log_level),
             section("network", &Loader::network),
             section("protection", &Loader::protection),
             section("memory", &Loader::memory),
             section("storage", &Loader::storage),
             section("inject", &Loader::inject),
             section("files", &Loader::files),
             {"serial", Type::any,
              [this](const Entry& e) { return load_serial_table(e.node, source_, s_.serial); }},
             {"plc", Type::any,
              [this](const Entry& e) { return load_plant(e.key, e.node, source_, s_); }},
             {"remote", Type::any,
              [this](const Entry& e) { return load_remotes(e.key, e.node, source_, s_); }},
             {"schedule", Type::any,
              [this](const Entry& e) { return load_schedule(e.key, e.node, source_, s_); }},
             {"http", Type::any,
              [this](const Entry& e) { return load_http_table(e.node, source_, s_.http); }},
             {"scenario", Type::any, [this](const Entry& e) { return scenario(e.node); }}});
    }

    // A [[plc]]'s own [protection], [inject], [storage] or [files] table.
    Expected<void> cpu_section(const toml::key& key, const toml::node& node, const std::string& p) {
        const config::Table how(source_, "", At::key);
        const Entry e{key, node, p, how};
        if (!node.is_table()) return e.fail("must be a table");
        if (key.str() == "protection") return protection(e);
        if (key.str() == "inject") return inject(e);
        if (key.str() == "storage") return storage(e);
        if (key.str() == "files") return files(e);
        return e.fail("unknown key");
    }

  private:
    Key section(std::string_view name, Expected<void> (Loader::*read)(const Entry&)) {
        return {name, Type::table, [this, read](const Entry& e) { return (this->*read)(e); }};
    }
    static Key path_key(std::string_view name, std::optional<std::filesystem::path>& out) {
        return {name, Type::string, [&out](const Entry& e) -> Expected<void> {
                    if (e.text().empty()) return e.fail("must not be empty");
                    out = e.text();
                    return {};
                }};
    }
    tl::unexpected<Error> fail(const toml::key& key, std::string_view path,
                               std::string_view message) const {
        return config::fail_at(source_, key.source(), path, message);
    }

    Expected<void> scenario(const toml::node& node) {
        auto config = load_scenario_table(node, source_, "scenario");
        if (!config) return tl::unexpected(config.error());
        s_.scenario = std::move(*config);
        return {};
    }

    Expected<void> mode(const Entry& e) {
        const auto m = parse_mode(e.text());
        if (!m) return e.fail(fmt::format("'{}' is not program, monitor or run", e.text()));
        s_.mode = *m;
        return {};
    }

    Expected<void> network(const Entry& e) {
        return config::read_table(
            e, {config::text_key("bind", s_.bind), config::flag_key("udp", s_.udp),
                config::flag_key("tcp", s_.tcp), config::integer_key("node", s_.node, 0, 254),
                config::integer_key("network", s_.network, 0, 127),
                config::integer_key("port", s_.port, 0, 65535),
                config::integer_key("max_connections", s_.max_connections, 1, 254),
                config::integer_key("tcp_handshake_timeout", s_.tcp_handshake_timeout, 1, 3600),
                config::integer_key("tcp_frame_timeout", s_.tcp_frame_timeout, 1, 3600),
                config::integer_key("tcp_idle_timeout", s_.tcp_idle_timeout, 0, 86400),
                config::integer_key("tcp_keepalive", s_.tcp_keepalive, 0, 7200),
                config::integer_key("tcp_max_pending", s_.tcp_max_pending, 1, 1024)});
    }

    // [files] card = true/false, card_kbytes = 1-4194303, em_file_bank = 0-24,
    // cassette = true/false.
    Expected<void> files(const Entry& e) {
        return config::read_table(e, {{"card", Type::boolean,
                                       [this](const Entry& k) -> Expected<void> {
                                           if (!k.flag())
                                               s_.card_kbytes = 0;
                                           else if (s_.card_kbytes == 0u)
                                               s_.card_kbytes.reset();
                                           return {};
                                       }},
                                      {"card_kbytes", Type::integer,
                                       [this](const Entry& k) -> Expected<void> {
                                           const auto v = k.integer(1, 4194303);
                                           if (!v) return Fail(v.error());
                                           if (s_.card_kbytes != 0u)
                                               s_.card_kbytes = static_cast<std::uint32_t>(*v);
                                           return {};
                                       }},
                                      config::flag_key("cassette", s_.cassette),
                                      config::integer_key("em_file_bank", s_.em_file_bank, 0, 24)});
    }

    Expected<void> protection(const Entry& e) {
        return config::read_table(
            e, {config::flag_key("um_read", s_.um_read_protection),
                config::flag_key("dip_write", s_.dip_write_protection),
                {"password", Type::string,
                 [this](const Entry& k) -> Expected<void> {
                     // CJ2 CPU Units take 16 characters (CS/CJ 8); printable ASCII.
                     const std::string& value = k.text();
                     const bool printable = std::all_of(
                         value.begin(), value.end(), [](char c) { return c >= 0x20 && c < 0x7F; });
                     if (value.empty() || value.size() > 16 || !printable)
                         return k.fail("must be 1-16 printable ASCII characters");
                     s_.um_password = value;
                     return {};
                 }},
                {"network_write", Type::string,
                 [this](const Entry& k) -> Expected<void> {
                     const auto mode = parse_protection(k.text());
                     if (!mode)
                         return k.fail(fmt::format(
                             "'{}' is not off, all, listed or all-except-listed", k.text()));
                     s_.network_write_protection.mode = *mode;
                     return {};
                 }},
                {"nodes", Type::any, [this](const Entry& k) { return protected_nodes(k); }}});
    }

    Expected<void> protected_nodes(const Entry& e) {
        const auto* list = e.node.as_array();
        if (list == nullptr) return e.fail("must be an array of \"network.node\" strings");
        if (list->size() > plc::max_protection_nodes)
            return e.fail(fmt::format("more than {} nodes", plc::max_protection_nodes));
        s_.network_write_protection.nodes.clear();
        for (std::size_t i = 0; i < list->size(); ++i) {
            const auto* item = (*list)[i].as_string();
            const auto n = item != nullptr ? parse_node(item->get()) : std::nullopt;
            if (!n)
                return fail(e.key, fmt::format("{}[{}]", e.path, i),
                            "must be \"network.node\" (network 0-127, node 1-254 or *)");
            s_.network_write_protection.nodes.push_back(*n);
        }
        return {};
    }

    Expected<void> storage(const Entry& e) {
        return config::read_table(
            e, {{"durability", Type::string, [this](const Entry& k) -> Expected<void> {
                     const auto d = parse_durability(k.text());
                     if (!d) return k.fail(fmt::format("'{}' is not process or power", k.text()));
                     s_.durability = *d;
                     return {};
                 }}});
    }

    Expected<void> memory(const Entry& e) {
        for (const auto& [key, node] : config::in_file_order(*e.node.as_table())) {
            auto entry = memory_entry(*key, *node, source_, "memory");
            if (!entry) return tl::unexpected<Error>(entry.error());
            s_.memory.push_back(std::move(*entry));
        }
        return {};
    }

    Expected<plc::FalInjection> fal(const toml::key& key, const toml::node& node,
                                    const std::string& p) const {
        const auto* t = node.as_table();
        if (t == nullptr) return fail(key, p, "must be { number = 1-511, message = \"...\" }");
        plc::FalInjection f;
        if (auto r = config::read_table(*t, {source_, p, At::key},
                                        {config::integer_key("number", f.number, 1, 511),
                                         config::text_key("message", f.message)});
            !r)
            return Fail(r.error());
        if (f.number == 0) return fail(key, p + ".number", "missing");
        return f;
    }

    Expected<void> inject(const Entry& e) {
        auto& in = s_.inject;
        // Each injection, once read, against the injections' own rules.
        const auto checked = [this](config::Reader read) -> config::Reader {
            return [this, read](const Entry& k) -> Expected<void> {
                if (auto r = read(k); !r) return r;
                return check_injections(k);
            };
        };
        return config::read_table(
            e, {config::flag_key("battery_error", in.battery_error),
                {"fals", Type::any, checked([this, &in](const Entry& k) -> Expected<void> {
                     const auto f = fal(k.key, k.node, k.path);
                     if (!f) return Fail(f.error());
                     in.fals = *f;
                     return {};
                 })},
                {"fal", Type::any, checked([this, &in](const Entry& k) -> Expected<void> {
                     const auto* list = k.node.as_array();
                     if (list == nullptr) return k.fail("must be an array of { number, message }");
                     in.fal.clear();
                     for (std::size_t i = 0; i < list->size(); ++i) {
                         const auto f = fal(k.key, (*list)[i], fmt::format("{}[{}]", k.path, i));
                         if (!f) return Fail(f.error());
                         in.fal.push_back(*f);
                     }
                     return {};
                 })},
                {"messages", Type::any, checked([this](const Entry& k) { return messages(k); })},
                {"errors", Type::any, checked([this, &in](const Entry& k) -> Expected<void> {
                     const auto* list = k.node.as_array();
                     if (list == nullptr) return k.fail("must be an array of error codes");
                     in.errors.clear();
                     for (std::size_t i = 0; i < list->size(); ++i) {
                         const std::string item = fmt::format("{}[{}]", k.path, i);
                         const auto* v = (*list)[i].as_integer();
                         if (v == nullptr) return fail(k.key, item, "must be an integer");
                         if (v->get() < 0 || v->get() > 0xFFFF)
                             return fail(k.key, item, fmt::format("{} is not 0-65535", v->get()));
                         in.errors.push_back(static_cast<std::uint16_t>(v->get()));
                     }
                     return {};
                 })}});
    }

    Expected<void> messages(const Entry& e) {
        const auto* t = e.node.as_table();
        if (t == nullptr) return e.fail("must be a table { 0 = \"text\", ... }");
        for (const auto& [key_ptr, node_ptr] : config::in_file_order(*t)) {
            const toml::key& n = *key_ptr;
            const std::string child = e.path + "." + std::string(n.str());
            const std::string_view digit = n.str();
            if (digit.size() != 1 || digit[0] < '0' || digit[0] > '7')
                return fail(n, child, "message numbers are 0-7");
            const auto* text = node_ptr->as_string();
            if (text == nullptr) return fail(n, child, "must be a string");
            s_.inject.messages[static_cast<std::size_t>(digit[0] - '0')] = text->get();
        }
        return {};
    }

    // The injections' own rules (plc/injections.hpp): "fal[0].message: longer than
    // 16 characters" becomes "inject.fal[0].message: longer than 16 characters".
    Expected<void> check_injections(const Entry& e) const {
        const auto error = plc::validate(s_.inject);
        if (error.empty()) return {};
        const auto colon = std::min(error.find(": "), error.size());
        // "inject." or "plc[N].inject.": the path up to this key.
        const std::string section = e.path.substr(0, e.path.rfind('.') + 1);
        return fail(e.key, section + error.substr(0, colon),
                    colon < error.size() ? std::string_view(error).substr(colon + 2) : "invalid");
    }

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
    const auto text = config::read_text_file(file);
    if (!text) return tl::unexpected<Error>(text.error());
    return load_config_text(*text, file.string(), settings);
}

}  // namespace fins::finsd
