// The fins-bridge TOML loader (config.hpp). Internally a failure is thrown as a Failure
// carrying "file:line:col: message" and turned into the error result at the top: the
// loader is not on any hot path and this keeps every check one line.
#include "bridge/config.hpp"
#include "bridge/config_loader.hpp"
#include "config/text_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "fins/commands/memory_area.hpp"
#include "fins/node_address.hpp"
#include "plc/profile.hpp"

namespace fins::bridge {

namespace detail {

BridgeConfig Loader::load(const toml::table& root, const std::string& instance) {
    only(root, "the file", {"bridge", "mqtt", "write", "plc"});
    BridgeConfig c;
    c.source = source_;
    if (const auto* n = root.get("bridge")) {
        const auto& t = table(*n, "[bridge]");
        only(t, "[bridge]", {"instance", "failover_s", "payload", "stats_s", "sparkplug_group"});
        c.sparkplug_group = text_or(t, "sparkplug_group", "");
        if (!c.sparkplug_group.empty() && !valid_name(c.sparkplug_group))
            fail(*t.get("sparkplug_group"), "sparkplug_group must be [A-Za-z0-9_-]+");
        c.instance = text_or(t, "instance", "");
        if (!c.instance.empty() && !valid_name(c.instance))
            fail(*t.get("instance"), "instance must be [A-Za-z0-9_-]+");
        duration(t, "failover_s", 1, 3600, c.failover);
        duration(t, "stats_s", 1, 3600, c.stats);
        c.payload = text_or(t, "payload", "json");
        if (c.payload != "json" && c.payload != "sparkplug")
            fail(*t.get("payload"), "payload must be \"json\" or \"sparkplug\"");
    }
    if (!instance.empty()) c.instance = instance;
    if (c.instance.empty()) {
        char host[256] = {};
        ::gethostname(host, sizeof host - 1);
        c.instance = host;
        std::replace_if(
            c.instance.begin(), c.instance.end(),
            [](char ch) { return !valid_name(std::string_view(&ch, 1)); }, '-');
    }
    if (const auto* n = root.get("mqtt")) mqtt(table(*n, "[mqtt]"), c.mqtt);
    if (c.mqtt.brokers.empty()) c.mqtt.brokers.push_back({"127.0.0.1", 1883});
    if (c.mqtt.client_id.empty()) c.mqtt.client_id = "fins-bridge-" + c.instance;
    if (c.sparkplug_group.empty()) {
        // Sparkplug's group_id: the topic prefix, with what a Sparkplug ID may not hold
        // ('/', '+', '#') made '-'.
        c.sparkplug_group = c.mqtt.topic_prefix;
        std::replace_if(
            c.sparkplug_group.begin(), c.sparkplug_group.end(),
            [](char ch) { return !valid_name(std::string_view(&ch, 1)); }, '-');
    }
    if (const auto* n = root.get("write")) {
        const auto& t = table(*n, "[write]");
        only(t, "[write]", {"ttl_s", "id_memory", "ts_skew_s"});
        if (auto v = integer(t, "ts_skew_s", 0, 3600)) c.write.ts_skew = std::chrono::seconds(*v);
        if (auto v = integer(t, "ttl_s", 1, 86400)) c.write.ttl = std::chrono::seconds(*v);
        if (auto v = integer(t, "id_memory", 1, 1000000))
            c.write.id_memory = static_cast<std::size_t>(*v);
    }
    if (const auto* n = root.get("plc")) {
        const auto* list = n->as_array();
        if (list == nullptr) fail(*n, "plc must be an array of tables: [[plc]]");
        std::set<std::string> names;
        for (const auto& p : *list) {
            c.plcs.push_back(plc(table(p, "[[plc]]")));
            if (!names.insert(c.plcs.back().name).second)
                fail(*p.as_table()->get("name"),
                     fmt::format("duplicate PLC name '{}'", c.plcs.back().name));
        }
    }
    if (c.plcs.empty()) fail(root.source(), "no [[plc]]: nothing to poll");
    return c;
}

void Loader::mqtt(const toml::table& t, Mqtt& m) {
    only(t, "[mqtt]",
         {"host", "port", "hosts", "client_id", "username", "password", "ca_file", "cert_file",
          "key_file", "tls_insecure", "keepalive_s", "topic_prefix", "qos", "queue_limit",
          "backoff_min_ms", "backoff_max_ms"});
    std::uint16_t port = 1883;
    const auto given_port = integer(t, "port", 1, 65535);
    if (given_port) port = static_cast<std::uint16_t>(*given_port);
    if (auto h = text(t, "host")) {
        if (h->empty()) fail(*t.get("host"), "host must not be empty");
        m.brokers.push_back({*h, port});
    } else if (given_port && t.get("hosts") == nullptr) {
        m.brokers.push_back({"127.0.0.1", port});  // port alone: the default host
    }
    if (const auto* n = t.get("hosts")) {
        const auto* list = n->as_array();
        if (list == nullptr || list->empty()) fail(*n, "hosts must be a list of \"host[:port]\"");
        for (const auto& e : *list) {
            const auto* s = e.as_string();
            if (s == nullptr) fail(e, "hosts must be a list of \"host[:port]\"");
            std::string h = s->get();
            Broker b{h, port};
            if (auto colon = h.rfind(':'); colon != std::string::npos) {
                unsigned p = 0;
                auto tail = std::string_view(h).substr(colon + 1);
                auto [end, ec] = std::from_chars(tail.data(), tail.data() + tail.size(), p);
                if (ec != std::errc{} || end != tail.data() + tail.size() || p == 0 || p > 65535)
                    fail(e, fmt::format("'{}': bad port", h));
                b = {h.substr(0, colon), static_cast<std::uint16_t>(p)};
            }
            if (b.host.empty()) fail(e, "empty host name");
            m.brokers.push_back(b);
        }
    }
    m.client_id = text_or(t, "client_id", "");
    m.username = text_or(t, "username", "");
    m.password = text_or(t, "password", "");
    m.ca_file = text_or(t, "ca_file", "");
    m.cert_file = text_or(t, "cert_file", "");
    m.key_file = text_or(t, "key_file", "");
    if ((m.cert_file.empty()) != (m.key_file.empty()))
        fail(t.source(), "cert_file and key_file go together");
    if (!m.cert_file.empty() && m.ca_file.empty())
        fail(t.source(), "a client certificate needs ca_file (TLS)");
    // Files named are read at start: one that cannot be is this file's error, not a TLS
    // failure at the first connect.
    for (const char* key : {"ca_file", "cert_file", "key_file"}) {
        const auto name = text_or(t, key, "");
        if (!name.empty() && ::access(name.c_str(), R_OK) != 0)
            fail(*t.get(key), fmt::format("{} '{}' cannot be read", key, name));
    }
    m.tls_insecure = boolean(t, "tls_insecure").value_or(false);
    duration(t, "keepalive_s", 5, 65535, m.keepalive);
    m.topic_prefix = text_or(t, "topic_prefix", "finskit");
    if (m.topic_prefix.empty() || m.topic_prefix.find_first_of("+#") != std::string::npos ||
        m.topic_prefix.back() == '/')
        fail(*t.get("topic_prefix"), "topic_prefix must be non-empty, without + # or a final /");
    if (auto v = integer(t, "qos", 0, 1)) m.qos = static_cast<int>(*v);
    if (auto v = integer(t, "queue_limit", 10, 10000000))
        m.queue_limit = static_cast<std::size_t>(*v);
    duration(t, "backoff_min_ms", 10, 600000, m.backoff_min);
    duration(t, "backoff_max_ms", 10, 3600000, m.backoff_max);
}

Plc Loader::plc(const toml::table& t) {
    only(t, "[[plc]]",
         {"name", "host", "port", "transport", "dest", "model", "timeout_ms", "retries", "window",
          "backoff_min_ms", "backoff_max_ms", "group"});
    Plc p;
    p.name = name(t, "[[plc]]");
    p.host = required_text(t, "host", fmt::format("plc '{}'", p.name));
    if (p.host.empty()) fail(*t.get("host"), "host must not be empty");
    if (auto v = integer(t, "port", 1, 65535)) p.port = static_cast<std::uint16_t>(*v);
    if (auto tr = text(t, "transport")) {
        if (*tr == "udp")
            p.transport = Transport::udp;
        else if (*tr == "tcp")
            p.transport = Transport::tcp;
        else
            fail(*t.get("transport"), "transport must be \"udp\" or \"tcp\"");
    }
    if (auto d = text(t, "dest")) p.dest = node_address(*t.get("dest"), *d);
    p.model = text_or(t, "model", "cj2h");
    profile_ = plc::find_profile(p.model);
    if (profile_ == nullptr) fail(*t.get("model"), fmt::format("unknown model '{}'", p.model));
    duration(t, "timeout_ms", 10, 60000, p.timeout);
    if (auto v = integer(t, "retries", 0, 10)) p.retries = static_cast<unsigned>(*v);
    if (auto v = integer(t, "window", 1, 64)) p.window = static_cast<std::size_t>(*v);
    duration(t, "backoff_min_ms", 10, 600000, p.backoff_min);
    duration(t, "backoff_max_ms", 10, 3600000, p.backoff_max);
    if (p.backoff_max < p.backoff_min) fail(t.source(), "backoff_max_ms below backoff_min_ms");
    const auto* g = t.get("group");
    if (g == nullptr) fail(t.source(), fmt::format("plc '{}' has no [[plc.group]]", p.name));
    const auto* list = g->as_array();
    if (list == nullptr) fail(*g, "group must be an array of tables: [[plc.group]]");
    std::set<std::string> names;
    std::set<std::string> tag_names;  // write commands name a tag per PLC: unique per PLC
    for (const auto& e : *list) {
        p.groups.push_back(group(table(e, "[[plc.group]]"), tag_names));
        if (!names.insert(p.groups.back().name).second)
            fail(*e.as_table()->get("name"),
                 fmt::format("duplicate group name '{}'", p.groups.back().name));
    }
    return p;
}

NodeAddress Loader::node_address(const toml::node& n, const std::string& s) const {
    unsigned v[3] = {};
    std::size_t at = 0;
    for (int i = 0; i < 3; ++i) {
        auto [end, ec] = std::from_chars(s.data() + at, s.data() + s.size(), v[i]);
        if (ec != std::errc{}) fail(n, fmt::format("dest '{}' must be \"net.node.unit\"", s));
        at = static_cast<std::size_t>(end - s.data());
        if (i < 2) {
            if (at >= s.size() || s[at] != '.')
                fail(n, fmt::format("dest '{}' must be \"net.node.unit\"", s));
            ++at;
        }
    }
    if (at != s.size()) fail(n, fmt::format("dest '{}' must be \"net.node.unit\"", s));
    if (v[0] > 127) fail(n, "dest network must be 0-127");
    if (v[1] > 254) fail(n, "dest node must be 0-254");
    if (v[2] > 255) fail(n, "dest unit must be 0-255");
    return {static_cast<std::uint8_t>(v[0]), static_cast<std::uint8_t>(v[1]),
            static_cast<std::uint8_t>(v[2])};
}

Group Loader::group(const toml::table& t, std::set<std::string>& tag_names) {
    only(t, "[[plc.group]]",
         {"name", "interval_ms", "publish", "deadband", "integrity_s", "gap_words", "tags"});
    Group g;
    g.name = name(t, "[[plc.group]]");
    if (g.name == "status" || g.name == "write" || g.name == "$bridge")
        fail(*t.get("name"), fmt::format("group name '{}' is reserved (a topic)", g.name));
    duration(t, "interval_ms", 10, 3600000, g.interval);
    if (auto p = text(t, "publish")) {
        if (*p == "change")
            g.publish = Publish::change;
        else if (*p == "always")
            g.publish = Publish::always;
        else
            fail(*t.get("publish"), "publish must be \"change\" or \"always\"");
    }
    if (auto d = number(t, "deadband")) {
        if (*d < 0) fail(*t.get("deadband"), "deadband must not be negative");
        g.deadband = *d;
    }
    duration(t, "integrity_s", 1, 86400, g.integrity);
    if (auto v = integer(t, "gap_words", 0, max_read_words))
        g.gap_words = static_cast<std::size_t>(*v);
    const auto* n = t.get("tags");
    if (n == nullptr) fail(t.source(), fmt::format("group '{}' has no tags", g.name));
    const auto* list = n->as_array();
    if (list == nullptr || list->empty()) fail(*n, "tags must be a non-empty list of tables");
    for (const auto& e : *list) {
        g.tags.push_back(tag(table(e, "a tag")));
        if (!tag_names.insert(g.tags.back().name).second)
            fail(*e.as_table()->get("name"),
                 fmt::format("duplicate tag name '{}' in this PLC", g.tags.back().name));
    }
    return g;
}

}  // namespace detail

using detail::Failure;
using detail::Loader;

bool valid_name(std::string_view name) {
    if (name.empty()) return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '-';
    });
}

tl::expected<BridgeConfig, std::string> parse_config(const std::string& text,
                                                     const std::string& source,
                                                     const std::string& instance) {
    toml::table root;
    try {
        root = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        return tl::unexpected(fmt::format("{}:{}:{}: {}", source, e.source().begin.line,
                                          e.source().begin.column, e.description()));
    }
    try {
        return Loader(source).load(root, instance);
    } catch (const Failure& f) {
        return tl::unexpected(f.message);
    }
}

tl::expected<BridgeConfig, std::string> load_config(const std::string& path,
                                                    const std::string& instance) {
    const auto text = config::read_text_file(path);
    if (!text) return tl::unexpected(text.error());
    return parse_config(*text, path, instance);
}

}  // namespace fins::bridge
