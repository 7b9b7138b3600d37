// [[remote]] and [[schedule]] (config_schedule.hpp).
#include "finsd/config_schedule.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>

#include <fmt/format.h>
#include <boost/asio/ip/address.hpp>

#include "codec/hex.hpp"
#include "config/schema.hpp"
#include "finsd/config.hpp"
#include "transport/asio.hpp"

namespace fins::finsd {

namespace {

using Fail = tl::unexpected<std::string>;
using Done = tl::expected<void, std::string>;
using config::Entry;
using config::Key;
using config::Type;

std::string at(std::string_view source, const toml::source_region& where) {
    return fmt::format("{}:{}:{}", source, where.begin.line, where.begin.column);
}

// The entries of an array of tables, or why not.
tl::expected<const toml::array*, std::string> tables(const toml::key& key, const toml::node& node,
                                                     std::string_view source) {
    const auto* list = node.as_array();
    if (list == nullptr || !list->is_array_of_tables())
        return Fail(fmt::format("{}: {}: must be an array of tables ([[{}]])",
                                at(source, key.source()), key.str(), key.str()));
    return list;
}

std::optional<std::chrono::milliseconds> parse_period(std::string_view text) {
    std::size_t digits = 0;
    while (digits < text.size() && std::isdigit(static_cast<unsigned char>(text[digits])) != 0)
        ++digits;
    if (digits == 0 || digits > 9) return std::nullopt;
    const auto n = std::stoull(std::string(text.substr(0, digits)));
    const auto unit = text.substr(digits);
    if (unit == "ms") return std::chrono::milliseconds(n);
    if (unit == "s") return std::chrono::milliseconds(n * 1000);
    if (unit == "min") return std::chrono::milliseconds(n * 60'000);
    return std::nullopt;
}

// "IP:PORT", "[IPv6]:PORT" or an IP alone (port 9600).
std::optional<std::pair<std::string, std::uint16_t>> parse_host_port(const std::string& text) {
    std::string host = text;
    std::string port_text;
    bool has_port = false;
    if (!text.empty() && text.front() == '[') {
        const auto close = text.find(']');
        if (close == std::string::npos) return std::nullopt;
        host = text.substr(1, close - 1);
        const auto rest = text.substr(close + 1);
        if (!rest.empty()) {
            if (rest[0] != ':') return std::nullopt;
            port_text = rest.substr(1);
            has_port = true;
        }
    } else if (std::count(text.begin(), text.end(), ':') == 1) {
        const auto colon = text.find(':');
        host = text.substr(0, colon);
        port_text = text.substr(colon + 1);
        has_port = true;
    }
    std::uint16_t port = 9600;
    if (has_port) {
        unsigned v = 0;
        const auto* end = port_text.data() + port_text.size();
        const auto r = std::from_chars(port_text.data(), end, v);
        if (port_text.empty() || r.ec != std::errc{} || r.ptr != end || v == 0 || v > 65535)
            return std::nullopt;
        port = static_cast<std::uint16_t>(v);
    }
    boost::system::error_code ec;
    asio::ip::make_address(host, ec);
    if (host.empty() || ec) return std::nullopt;
    return std::pair{host, port};
}

}  // namespace

tl::expected<void, std::string> load_remotes(const toml::key& key, const toml::node& node,
                                             std::string_view source, Settings& settings) {
    const auto list = tables(key, node, source);
    if (!list) return Fail(list.error());
    for (std::size_t i = 0; i < (*list)->size(); ++i) {
        const auto& t = *(**list)[i].as_table();
        const std::string p = fmt::format("remote[{}]", i);
        server::RemoteNode r;
        const auto integer = [&](std::string_view name, std::int64_t lo, std::int64_t hi,
                                 std::string_view why, std::uint8_t& out) -> Key {
            return {name, Type::any, [lo, hi, why, &out](const Entry& e) -> Done {
                        const auto* n = e.node.as_integer();
                        if (n == nullptr || n->get() < lo || n->get() > hi) return e.fail(why);
                        out = static_cast<std::uint8_t>(n->get());
                        return {};
                    }};
        };
        auto read = config::read_table(
            t, {source, p},
            {{"transport", Type::any,
              [&](const Entry& e) -> Done {
                  const auto* s = e.node.as_string();
                  if (s == nullptr || (s->get() != "udp" && s->get() != "tcp"))
                      return e.fail("must be \"udp\" or \"tcp\"");
                  r.tcp = s->get() == "tcp";
                  return {};
              }},
             integer("client_node", 0, 254,
                     "must be an integer 0-254 (0: the server allocates one)", r.client_node),
             integer("node", 1, 254, "must be an integer 1-254", r.node),
             integer("network", 0, 127, "must be an integer 0-127", r.network),
             {"address", Type::any, [&](const Entry& e) -> Done {
                  const auto* s = e.node.as_string();
                  const auto hp = s != nullptr ? parse_host_port(s->get()) : std::nullopt;
                  if (!hp)
                      return e.fail(
                          "must be \"IP:PORT\" (\"127.0.1.5:9600\", \"[::1]:9600\") or an IP");
                  r.host = hp->first;
                  r.port = hp->second;
                  return {};
              }}});
        if (!read) return read;
        const bool has_node = t.contains("node"), has_address = t.contains("address");
        const bool has_client_node = t.contains("client_node");
        if (!has_node || !has_address)
            return Fail(fmt::format("{}: {}: needs node and address", at(source, t.source()), p));
        if (has_client_node && !r.tcp)
            return Fail(fmt::format("{}: {}: client_node needs transport = \"tcp\"",
                                    at(source, t.source()), p));
        const auto same_connection = [&](const server::RemoteNode& o) {
            return o.tcp && o.network == r.network && o.node == r.node;
        };
        if (r.tcp && std::any_of(settings.remotes.begin(), settings.remotes.end(), same_connection))
            return Fail(fmt::format("{}: {}: node {}.{} already has a FINS/TCP connection",
                                    at(source, t.source()), p, r.network, r.node));
        settings.remotes.push_back(std::move(r));
    }
    return {};
}

tl::expected<void, std::string> load_schedule(const toml::key& key, const toml::node& node,
                                              std::string_view source, Settings& settings) {
    const auto list = tables(key, node, source);
    if (!list) return Fail(list.error());
    for (std::size_t i = 0; i < (*list)->size(); ++i) {
        const auto& t = *(**list)[i].as_table();
        const std::string p = fmt::format("schedule[{}]", i);
        if (settings.schedule.size() >= server::max_scheduled_instructions)
            return Fail(
                fmt::format("{}: {}: at most {} [[schedule]] entries (W596: 32 "
                            "instructions at once)",
                            at(source, t.source()), p, server::max_scheduled_instructions));
        ScheduleEntry e;
        e.where = at(source, t.source());
        auto& r = e.scheduled.request;
        // A string the parser `parse` takes, or the complaint `why`.
        const auto parsed = [](std::string_view name, std::string_view why, auto parse) -> Key {
            return {name, Type::any, [why, parse](const Entry& k) -> Done {
                        const auto* s = k.node.as_string();
                        if (s == nullptr || !parse(s->get())) return k.fail(why);
                        return {};
                    }};
        };
        const auto count = [](std::string_view name, std::int64_t hi, auto set) -> Key {
            return {name, Type::any, [hi, set](const Entry& k) -> Done {
                        const auto* n = k.node.as_integer();
                        if (n == nullptr || n->get() < 0 || n->get() > hi)
                            return k.fail(fmt::format("must be an integer 0-{}", hi));
                        set(n->get());
                        return {};
                    }};
        };
        const auto word_address = [&](Address& out) {
            return [&out](const std::string& s) {
                auto a = parse_address(s);
                if (a) out = *a;
                return a.has_value();
            };
        };
        auto read = config::read_table(
            t, {source, p},
            {parsed("every", "must be a period of 10ms or more: \"250ms\", \"1s\", \"1min\"",
                    [&](const std::string& s) {
                        const auto period = parse_period(s);
                        if (!period || *period < server::min_schedule_period) return false;
                        e.scheduled.every = *period;
                        return true;
                    }),
             parsed("instruction", "must be send, recv or sendcmd",
                    [&](const std::string& s) {
                        const auto kind = server::parse_instruction_kind(s);
                        if (kind) r.kind = *kind;
                        return kind.has_value();
                    }),
             parsed("dest", "must be NET.NODE.UNIT (network 0-127)",
                    [&](const std::string& s) {
                        const auto d = server::parse_destination(s);
                        if (d) r.destination = *d;
                        return d.has_value();
                    }),
             parsed("local", "must be a word address such as D100", word_address(r.local)),
             parsed("remote", "must be a word address such as D100", word_address(r.remote)),
             parsed("command", "must be hex bytes: MRC SRC parameters",
                    [&](const std::string& s) {
                        auto bytes = hex::parse_bytes(s, " ");
                        if (!bytes || bytes->size() < 2) return false;
                        r.command = std::move(*bytes);
                        return true;
                    }),
             count("count", server::max_instruction_words,
                   [&](std::int64_t c) { r.count = static_cast<std::uint16_t>(c); }),
             count("timeout", 65535,
                   [&](std::int64_t c) { r.options.timeout = static_cast<std::uint16_t>(c); }),
             count("retries", server::max_instruction_retries,
                   [&](std::int64_t c) { r.options.retries = static_cast<unsigned>(c); }),
             config::flag_key("no_response", r.options.no_response)});
        if (!read) return read;
        const bool has_every = t.contains("every"), has_kind = t.contains("instruction"),
                   has_dest = t.contains("dest"), has_local = t.contains("local"),
                   has_remote = t.contains("remote"), has_command = t.contains("command");
        if (!has_every || !has_kind || !has_dest)
            return Fail(fmt::format("{}: {}: needs every, instruction and dest", e.where, p));
        const bool words = r.kind != server::InstructionKind::sendcmd;
        if (words && (!has_local || !has_remote || has_command))
            return Fail(fmt::format("{}: {}: {} needs local and remote (and no command)", e.where,
                                    p, server::instruction_kind_name(r.kind)));
        if (!words && (!has_command || has_local || has_remote))
            return Fail(
                fmt::format("{}: {}: sendcmd needs command (and no local/remote)", e.where, p));
        if (words && t.find("count") == t.end()) r.count = 1;
        settings.schedule.push_back(std::move(e));
    }
    return {};
}

tl::expected<void, std::string> check_schedule(const Settings& settings,
                                               const plc::IoMemory& memory) {
    // W596 1-4: the connection limit counts server and client connections.
    const auto clients = static_cast<std::size_t>(std::count_if(
        settings.remotes.begin(), settings.remotes.end(), [](const auto& r) { return r.tcp; }));
    if (clients > settings.max_connections)
        return Fail(
            fmt::format("{} [[remote]] entries with transport = \"tcp\", but "
                        "max_connections is {} (W596 1-4: server and client "
                        "connections together)",
                        clients, settings.max_connections));
    for (std::size_t i = 0; i < settings.schedule.size(); ++i) {
        const auto& e = settings.schedule[i];
        if (const auto why = server::check_instruction(e.scheduled.request, memory))
            return Fail(fmt::format("{}: schedule[{}]: {}", e.where, i, *why));
    }
    return {};
}

}  // namespace fins::finsd
