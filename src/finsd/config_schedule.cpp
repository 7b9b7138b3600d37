// [[remote]] and [[schedule]] (config_schedule.hpp).
#include "finsd/config_schedule.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>

#include <fmt/format.h>
#include <boost/asio/ip/address.hpp>

#include "finsd/config.hpp"
#include "transport/asio.hpp"

namespace fins::finsd {

namespace {

using Fail = tl::unexpected<std::string>;

std::string at(std::string_view source, const toml::source_region& where) {
    return fmt::format("{}:{}:{}", source, where.begin.line, where.begin.column);
}

Fail fail(std::string_view source, const toml::node& node, const std::string& path,
          std::string_view message) {
    return Fail(fmt::format("{}: {}: {}", at(source, node.source()), path, message));
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
        bool has_node = false, has_address = false, has_client_node = false;
        for (auto&& [k, v] : t) {
            const std::string path = p + "." + std::string(k.str());
            if (k == "transport") {
                const auto* s = v.as_string();
                if (s == nullptr || (s->get() != "udp" && s->get() != "tcp"))
                    return fail(source, v, path, "must be \"udp\" or \"tcp\"");
                r.tcp = s->get() == "tcp";
            } else if (k == "client_node") {
                const auto* n = v.as_integer();
                if (n == nullptr || n->get() < 0 || n->get() > 254)
                    return fail(source, v, path,
                                "must be an integer 0-254 (0: the server allocates one)");
                r.client_node = static_cast<std::uint8_t>(n->get());
                has_client_node = true;
            } else if (k == "node" || k == "network") {
                const auto* n = v.as_integer();
                const std::int64_t hi = k == "node" ? 254 : 127;
                const std::int64_t lo = k == "node" ? 1 : 0;
                if (n == nullptr || n->get() < lo || n->get() > hi)
                    return fail(source, v, path, fmt::format("must be an integer {}-{}", lo, hi));
                (k == "node" ? r.node : r.network) = static_cast<std::uint8_t>(n->get());
                has_node = has_node || k == "node";
            } else if (k == "address") {
                const auto* s = v.as_string();
                const auto hp = s != nullptr ? parse_host_port(s->get()) : std::nullopt;
                if (!hp)
                    return fail(
                        source, v, path,
                        "must be \"IP:PORT\" (\"127.0.1.5:9600\", \"[::1]:9600\") or an IP");
                const auto& [host, port] = *hp;
                r.host = host;
                r.port = port;
                has_address = true;
            } else {
                return fail(source, v, path, "unknown key");
            }
        }
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
        bool has_every = false, has_kind = false, has_dest = false, has_local = false,
             has_remote = false, has_command = false;
        for (auto&& [k, v] : t) {
            const std::string path = p + "." + std::string(k.str());
            const auto* s = v.as_string();
            const auto* n = v.as_integer();
            const toml::node& value = v;  // clang 14 cannot capture a structured binding
            const auto integer = [&](std::int64_t hi) -> tl::expected<std::int64_t, std::string> {
                if (n == nullptr || n->get() < 0 || n->get() > hi)
                    return fail(source, value, path, fmt::format("must be an integer 0-{}", hi));
                return n->get();
            };
            if (k == "every") {
                const auto period = s ? parse_period(s->get()) : std::nullopt;
                if (!period || *period < server::min_schedule_period)
                    return fail(source, v, path,
                                "must be a period of 10ms or more: \"250ms\", \"1s\", \"1min\"");
                e.scheduled.every = *period;
                has_every = true;
            } else if (k == "instruction") {
                const auto kind = s ? server::parse_instruction_kind(s->get()) : std::nullopt;
                if (!kind) return fail(source, v, path, "must be send, recv or sendcmd");
                r.kind = *kind;
                has_kind = true;
            } else if (k == "dest") {
                const auto d = s ? server::parse_destination(s->get()) : std::nullopt;
                if (!d) return fail(source, v, path, "must be NET.NODE.UNIT (network 0-127)");
                r.destination = *d;
                has_dest = true;
            } else if (k == "local" || k == "remote") {
                auto a =
                    s ? parse_address(s->get()) : Result<Address>{Unexpected(std::error_code{})};
                if (!a) return fail(source, v, path, "must be a word address such as D100");
                (k == "local" ? r.local : r.remote) = *a;
                (k == "local" ? has_local : has_remote) = true;
            } else if (k == "command") {
                std::string hex = s ? s->get() : "x";
                std::erase(hex, ' ');
                std::vector<std::uint8_t> bytes;
                bool ok = hex.size() % 2 == 0 && hex.size() >= 4;
                for (std::size_t b = 0; ok && b < hex.size(); b += 2) {
                    unsigned x = 0;
                    ok = std::sscanf(hex.substr(b, 2).c_str(), "%2x", &x) == 1 &&
                         std::isxdigit(static_cast<unsigned char>(hex[b])) != 0 &&
                         std::isxdigit(static_cast<unsigned char>(hex[b + 1])) != 0;
                    bytes.push_back(static_cast<std::uint8_t>(x));
                }
                if (!ok) return fail(source, v, path, "must be hex bytes: MRC SRC parameters");
                r.command = std::move(bytes);
                has_command = true;
            } else if (k == "count") {
                const auto c = integer(server::max_instruction_words);
                if (!c) return Fail(c.error());
                r.count = static_cast<std::uint16_t>(*c);
            } else if (k == "timeout") {
                const auto c = integer(65535);
                if (!c) return Fail(c.error());
                r.options.timeout = static_cast<std::uint16_t>(*c);
            } else if (k == "retries") {
                const auto c = integer(server::max_instruction_retries);
                if (!c) return Fail(c.error());
                r.options.retries = static_cast<unsigned>(*c);
            } else if (k == "no_response") {
                const auto* b = v.as_boolean();
                if (b == nullptr) return fail(source, v, path, "must be true or false");
                r.options.no_response = b->get();
            } else {
                return fail(source, v, path, "unknown key");
            }
        }
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
