// finsd's HTTP front at start-up (contract in web_setup.hpp).
#include "finsd/web_setup.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <fstream>
#include <memory>
#include <sstream>
#include <unordered_map>
#include <utility>

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "config/text_file.hpp"
#include "server/metrics/metrics.hpp"
#include "server/routing/plant.hpp"
#include "server/routing/router.hpp"
#include "server/sessions/server.hpp"

namespace fins::finsd {

namespace {

using Json = nlohmann::json;

// The token: the file's first line, without surrounding white space.
std::optional<std::string> read_token(const std::filesystem::path& file, std::string& why) {
    // A token is a line; 64 KiB bounds what a wrong path (/dev/zero) can make finsd read.
    const auto text = config::read_text_file(file, 64 * 1024);
    if (!text) {
        why = fmt::format(
            "--http-token-file {}: cannot read it{}", file.string(),
            text.error().find("larger than") != std::string::npos ? ": larger than 64 KiB" : "");
        return std::nullopt;
    }
    const std::string line = text->substr(0, text->find('\n'));
    const auto first = line.find_first_not_of(" \t\r\n");
    const auto last = line.find_last_not_of(" \t\r\n");
    if (first == std::string::npos) {
        why = fmt::format("--http-token-file {}: the first line is empty", file.string());
        return std::nullopt;
    }
    return line.substr(first, last - first + 1);
}

// "2026-11-26T15:04:05Z": to the second, so an idle peer's entry does not change.
std::string utc_text(std::chrono::system_clock::time_point t) {
    const std::time_t seconds = std::chrono::system_clock::to_time_t(t);
    std::tm utc{};
    ::gmtime_r(&seconds, &utc);
    return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z", utc.tm_year + 1900, utc.tm_mon + 1,
                       utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec);
}

}  // namespace

WebStart start_web(boost::asio::io_context& io, const HttpSettings& http,
                   std::vector<server::ControlTarget> targets, std::vector<UnitServers> units,
                   server::Plant* plant) {
    WebStart out;
    if (!http.listen) return out;
    const auto listen = parse_http_listen(*http.listen);
    if (!listen) {
        out.exit_code = 2;
        out.error = listen.error();
        return out;
    }
    web::WebContext context;
    context.options.bind_address = listen->first;
    context.options.port = listen->second;
    context.options.control = http.control;
    context.options.allowed_hosts = http.allowed_hosts;
    context.options.allowed_origins = http.allowed_origins;
    context.options.max_connections = http.max_connections;
    context.options.websocket_idle_timeout = http.websocket_idle_timeout;
    if (http.token_file) {
        std::string why;
        const auto token = read_token(*http.token_file, why);
        if (!token) {
            out.exit_code = 2;
            out.error = why;
            return out;
        }
        context.options.token = *token;
    }
    context.targets = std::move(targets);
    // Each CPU Unit's Ethernet units, found by its Plc in constant time: a plant's listing
    // asks this once per CPU Unit (a linear search made 10,000 units 10^8 comparisons).
    auto units_by_plc = std::make_shared<std::unordered_map<const plc::Plc*, UnitServers>>();
    for (std::size_t i = 0; i < context.targets.size() && i < units.size(); ++i)
        units_by_plc->emplace(context.targets[i].plc, units[i]);
    const auto units_of = [units_by_plc](const server::ControlTarget& t) -> const UnitServers* {
        const auto found = units_by_plc->find(t.plc);
        return found == units_by_plc->end() || found->second.empty() ? nullptr : &found->second;
    };
    // A plant's relay counts of a CPU Unit by end code: {"0000": passed, "0501": refused}.
    const auto relays_of = [plant](const server::ControlTarget& t) {
        Json relays = Json::object();
        if (plant != nullptr)
            for (const auto& [code, n] : plant->router().relay_counts(*t.plc))
                relays[fmt::format("{:04X}", code)] = n;
        return relays;
    };
    // Every Ethernet unit's FINS/TCP connections and FINS/UDP peers, each with the network
    // of the unit it came to; the peers newest first across the units.
    context.network_status = [units_of, relays_of](const server::ControlTarget& t, Json& status) {
        status["relays"] = relays_of(t);
        const auto* servers = units_of(t);
        if (servers == nullptr) return;
        Json list = Json::array();
        std::vector<std::pair<server::UdpPeerInfo, std::uint8_t>> peers;
        for (const auto* s : *servers) {
            const auto network = s->address().network;
            for (const auto& c : s->tcp_connection_list()) {
                Json entry{{"address", c.address},
                           {"port", c.port},
                           {"state", c.established ? "established" : "handshake"},
                           {"network", network}};
                entry["node"] = c.established ? Json(c.node) : Json(nullptr);
                list.push_back(std::move(entry));
            }
            for (auto& p : s->udp_peer_list())
                peers.emplace_back(std::move(p), network);
        }
        status["connections"] = std::move(list);
        std::stable_sort(peers.begin(), peers.end(), [](const auto& a, const auto& b) {
            return a.first.last_seen > b.first.last_seen;
        });
        Json peer_list = Json::array();
        for (const auto& [p, network] : peers)
            peer_list.push_back({{"address", p.address},
                                 {"port", p.port},
                                 {"node", p.node},
                                 {"network", network},
                                 {"last_seen", utc_text(p.last_seen)}});
        status["udp_peers"] = std::move(peer_list);
    };
    // The listing: the first unit's ports (what a client of the CPU Unit addresses first),
    // every unit's ports and address, and the TCP connections of them all.
    context.describe = [units_of, relays_of](const server::ControlTarget& t, Json& entry) {
        entry["relays"] = relays_of(t);
        const auto* servers = units_of(t);
        if (servers == nullptr) return;
        entry["udp_port"] = servers->front()->udp_port();
        entry["tcp_port"] = servers->front()->tcp_port();
        std::size_t connections = 0;
        Json list = Json::array();
        for (const auto* s : *servers) {
            const auto a = s->address();
            list.push_back({{"network", a.network},
                            {"node", a.node},
                            {"udp_port", s->udp_port()},
                            {"tcp_port", s->tcp_port()},
                            {"tcp_connections", s->tcp_connections()}});
            connections += s->tcp_connections();
        }
        entry["tcp_connections"] = connections;
        entry["ethernet_units"] = std::move(list);
    };
    // The server the metrics below describe, known once it started (it owns this hook).
    auto web_server = std::make_shared<const web::HttpServer*>(nullptr);
    context.metrics = [units, web_server]() {
        using server::metrics::Family;
        Family tcp{"fins_tcp_connections", "FINS/TCP client connections by state", "gauge", {}};
        std::size_t established = 0;
        std::size_t handshake = 0;
        for (const auto& of_cpu : units)
            for (const auto* s : of_cpu)
                for (const auto& c : s->tcp_connection_list())
                    ++(c.established ? established : handshake);
        tcp.samples = {{"state=\"established\"", static_cast<double>(established)},
                       {"state=\"handshake\"", static_cast<double>(handshake)}};
        Family web{"fins_web_connections", "Open HTTP and WebSocket connections", "gauge", {}};
        if (*web_server != nullptr) {
            const auto all = (*web_server)->connections();
            const auto websockets = (*web_server)->websockets();
            web.samples = {
                {"kind=\"http\"", static_cast<double>(all > websockets ? all - websockets : 0)},
                {"kind=\"websocket\"", static_cast<double>(websockets)}};
        }
        const std::vector<Family> extra{tcp, web};
        return server::metrics::expose(server::metrics::process_metrics(), extra);
    };
    auto started = web::HttpServer::start(io, std::move(context));
    if (!started) {
        out.exit_code = 3;
        out.error = fmt::format("cannot listen for HTTP on {}: {}", *http.listen,
                                started.error().message());
        return out;
    }
    out.server = std::move(*started);
    *web_server = out.server.get();
    spdlog::info("finsd: HTTP on {} port {} (control {})", listen->first, out.server->port(),
                 http.control ? "on" : "off");
    return out;
}

}  // namespace fins::finsd
