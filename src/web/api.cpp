// finsd's HTTP API (contract in api.hpp).
#include "web/api.hpp"

#include "transport/socket_headers.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <exception>
#include <string>

#include <fmt/core.h>
#include <boost/url/parse.hpp>
#include <boost/url/url_view.hpp>

#include "plc/plc.hpp"
#include "server/control/control_dispatch.hpp"
#include "server/control/control_requests.hpp"
#include "server/control/control_scenario.hpp"
#include "web/api_scenario.hpp"
#include "web/assets.hpp"
#include "web/cpu_facts.hpp"
#include "web/memory_values.hpp"
#include "web/plc_listing.hpp"

namespace fins::web {

namespace {

using Json = nlohmann::json;

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return out;
}

// "host:port", "[v6]:port", "host" -> host (brackets removed).
std::string_view host_part(std::string_view hostport) {
    if (!hostport.empty() && hostport.front() == '[') {
        const auto end = hostport.find(']');
        return end == std::string_view::npos ? hostport : hostport.substr(1, end - 1);
    }
    const auto colon = hostport.rfind(':');
    return colon == std::string_view::npos ? hostport : hostport.substr(0, colon);
}

bool ip_literal(std::string_view host) {
    const std::string h(host);
    unsigned char buffer[16];
    return ::inet_pton(AF_INET, h.c_str(), buffer) == 1 ||
           ::inet_pton(AF_INET6, h.c_str(), buffer) == 1;
}

// An IP literal cannot be rebound by DNS; a name must be one we were told to answer to.
bool allowed_host(const WebOptions& options, std::string_view hostport) {
    const std::string host = lower(host_part(hostport));
    if (host.empty()) return false;
    if (ip_literal(host) || host == "localhost" || host == lower(options.bind_address)) return true;
    return std::any_of(options.allowed_hosts.begin(), options.allowed_hosts.end(),
                       [&](const std::string& h) { return lower(h) == host; });
}

// The page's own origin (scheme, host and port it was reached at: "http://" + Host) or
// one configured. Not any IP literal or port: a page on http://127.0.0.2:9000 is another
// site, and so is "null" (sandboxed frames, file: pages).
bool allowed_origin(const WebOptions& options, std::string_view origin,
                    std::optional<std::string_view> host) {
    const std::string o = lower(origin);
    if (host && !host->empty() && o == "http://" + lower(*host)) return true;
    return std::any_of(options.allowed_origins.begin(), options.allowed_origins.end(),
                       [&](const std::string& a) { return lower(a) == o; });
}

// application/json, any parameters (charset=utf-8), any case, optional spaces.
bool json_content_type(std::optional<std::string_view> content_type) {
    if (!content_type) return false;
    std::string_view t = content_type->substr(0, content_type->find(';'));
    while (!t.empty() && (t.back() == ' ' || t.back() == '\t'))
        t.remove_suffix(1);
    while (!t.empty() && (t.front() == ' ' || t.front() == '\t'))
        t.remove_prefix(1);
    return lower(t) == "application/json";
}

// Compares in time independent of where the first difference is.
bool same_secret(std::string_view a, std::string_view b) {
    unsigned char diff = a.size() == b.size() ? 0 : 1;
    for (std::size_t i = 0; i < a.size(); ++i)
        diff |= static_cast<unsigned char>(a[i] ^ (i < b.size() ? b[i] : 0));
    return diff == 0;
}

std::string content_type_of(std::string_view name) {
    const auto dot = name.rfind('.');
    const auto ext = dot == std::string_view::npos ? std::string_view{} : name.substr(dot + 1);
    return ext == "html"   ? "text/html; charset=utf-8"
           : ext == "js"   ? "text/javascript; charset=utf-8"
           : ext == "css"  ? "text/css; charset=utf-8"
           : ext == "json" ? "application/json"
           : ext == "yaml" ? "application/yaml"
           : ext == "svg"  ? "image/svg+xml"
           : ext == "png"  ? "image/png"
           : ext == "ico"  ? "image/x-icon"
                           : "application/octet-stream";
}

struct Query {
    std::string path;
    std::vector<std::pair<std::string, std::string>> params;
    [[nodiscard]] const std::string* find(std::string_view key) const {
        for (const auto& [k, v] : params)
            if (k == key) return &v;
        return nullptr;
    }
};

std::optional<Query> parse_target(std::string_view target) {
    auto parsed = boost::urls::parse_origin_form(target);
    if (!parsed) return std::nullopt;
    Query q;
    q.path = std::string(parsed->path());
    for (const auto& p : parsed->params())
        q.params.emplace_back(p.key, p.has_value ? p.value : std::string());
    return q;
}

// The CPU Unit a request names with plc= (the first without it).
const server::ControlTarget* target_of(const WebContext& context,
                                       std::optional<std::string_view> wanted, HttpAnswer& error) {
    std::string why;
    const auto* t = server::find_control_target(context.targets, wanted, why);
    if (t == nullptr) error = error_answer(404, why);
    return t;
}

std::optional<std::string_view> plc_param(const Query& q) {
    if (const auto* p = q.find("plc"); p != nullptr && !p->empty()) return std::string_view(*p);
    return std::nullopt;
}

HttpAnswer read_route(WebContext& context, const Query& q) {
    HttpAnswer error;
    const auto* t = target_of(context, plc_param(q), error);
    if (t == nullptr) return error;
    const auto* address = q.find("address");
    if (address == nullptr || address->empty()) return error_answer(400, "address= is required");
    std::size_t count = 1;
    if (const auto* c = q.find("count")) {
        const auto r = std::from_chars(c->data(), c->data() + c->size(), count);
        if (r.ec != std::errc{} || r.ptr != c->data() + c->size())
            return error_answer(400, fmt::format("count={}: not a number", *c));
    }
    const auto* as = q.find("as");
    auto query = make_query(t->plc->memory(), *address, count, as ? *as : "uint16");
    if (!query) return error_answer(query.error().status, query.error().message);
    auto values = read_values(t->plc->memory(), *query, std::chrono::system_clock::now());
    if (!values) return error_answer(values.error().status, values.error().message);
    return json_answer(200, Json{{"address", format_address(query->start)},
                                 {"as", query->as},
                                 {"values", std::move(*values)}});
}

HttpAnswer write_route(WebContext& context, std::string_view body) {
    if (!context.options.control)
        return error_answer(403, "control is off: finsd was started without --http-control");
    const Json j = Json::parse(body, nullptr, false);
    if (j.is_discarded() || !j.is_object())
        return error_answer(400, "the body must be a JSON object");
    std::optional<std::string_view> wanted;
    if (const auto it = j.find("plc"); it != j.end() && !it->is_null()) {
        if (!it->is_string()) return error_answer(400, "\"plc\" must be a string");
        wanted = it->get_ref<const std::string&>();
    }
    HttpAnswer error;
    const auto* t = target_of(context, wanted, error);
    if (t == nullptr) return error;
    const auto address = j.find("address");
    if (address == j.end() || !address->is_string())
        return error_answer(400, "\"address\" must be a string");
    std::string as = "uint16";
    if (const auto it = j.find("as"); it != j.end()) {
        if (!it->is_string()) return error_answer(400, "\"as\" must be a string");
        as = it->get<std::string>();
    }
    const auto values = j.find("values");
    if (values == j.end()) return error_answer(400, "\"values\" is required");
    auto written = write_values(t->plc->memory(), address->get<std::string>(), *values, as);
    if (!written) return error_answer(written.error().status, written.error().message);
    context.watches->touch_topics();  // the status topic shows it at the next tick
    return json_answer(200, Json{{"ok", true}, {"written", *written}});
}

// The running scenario's tags, types and events (api_scenario.hpp).
HttpAnswer scenario_route(const WebContext& context, const Query& q) {
    HttpAnswer error;
    const auto* t = target_of(context, plc_param(q), error);
    if (t == nullptr) return error;
    if (t->scenario == nullptr)
        return error_answer(404,
                            "this CPU Unit runs no scenario (finsd --scenario FILE, or a "
                            "[scenario] table)");
    return json_answer(200, scenario_object(*t));
}

void control_route(WebContext& context, std::string_view body,
                   const std::function<void(HttpAnswer)>& done) {
    if (!context.options.control)
        return done(error_answer(403, "control is off: finsd was started without --http-control"));
    const Json j = Json::parse(body, nullptr, false);
    if (j.is_discarded()) return done(error_answer(400, "the body is not JSON"));
    server::dispatch_control_request(context.targets, j, [done, &context](Json reply) {
        context.watches->touch_topics();  // a mode, a fault, a FAL: shown at the next tick
        // The channel's own answer, as the Unix socket gives it; a refusal is a 400, a
        // failure of the server's (the boundary's "internal": true) a 500.
        const bool refused = reply.contains("error") && !reply.contains("result");
        const bool internal = reply.contains("internal");
        done(json_answer(internal ? 500 : refused ? 400 : 200, reply));
    });
}

}  // namespace

HttpAnswer json_answer(unsigned status, const Json& body) {
    return HttpAnswer{status, "application/json",
                      body.dump(-1, ' ', false, Json::error_handler_t::replace)};
}

HttpAnswer error_answer(unsigned status, std::string_view message) {
    return json_answer(status, Json{{"error", message}});
}

std::optional<HttpAnswer> check_request(const WebOptions& options, const RequestMeta& meta) {
    if (meta.host && !allowed_host(options, *meta.host))
        return error_answer(403, fmt::format("Host {} is not this server (loopback, an IP address "
                                             "or an allowed host name)",
                                             *meta.host));
    const bool changes = meta.method == "POST" || meta.websocket_upgrade;
    if (changes && meta.origin && !allowed_origin(options, *meta.origin, meta.host))
        return error_answer(403, fmt::format("Origin {} may not use this server (only the "
                                             "page's own origin or an allowed_origins entry)",
                                             *meta.origin));
    if (meta.method == "POST" && !options.token.empty()) {
        // The scheme is case-insensitive (RFC 9110 11.1): "bearer", "BEARER" too.
        constexpr std::string_view bearer = "bearer ";
        const auto auth = meta.authorization.value_or(std::string_view{});
        if (lower(auth.substr(0, bearer.size())) != bearer ||
            !same_secret(auth.substr(bearer.size()), options.token))
            return error_answer(403,
                                "this server needs \"Authorization: Bearer <token>\" "
                                "(the token of --http-token-file)");
    }
    if (meta.method == "POST" && !json_content_type(meta.content_type))
        return error_answer(415, "a POST needs \"Content-Type: application/json\"");
    return std::nullopt;
}

namespace {

// The error log's records, oldest first.
Json error_log(const server::ControlTarget& target) {
    const auto& errors = target.plc->errors();
    Json log = Json::array();
    for (std::size_t i = 0; i < errors.log_size(); ++i) {
        const auto& r = errors.log_record(i);
        log.push_back({{"code", fmt::format("{:04X}", r.error_code)},
                       {"detail", fmt::format("{:04X}", r.detail)},
                       {"time", fmt::format("20{:02}-{:02}-{:02} {:02}:{:02}:{:02}", r.time.year,
                                            r.time.month, r.time.day, r.time.hour, r.time.minute,
                                            r.time.second)}});
    }
    return log;
}

// The write access log's records.
Json access_log(const server::ControlTarget& target) {
    auto& log = target.plc->write_access_log();
    Json records = Json::array();
    for (std::size_t i = 0; i < log.size(); ++i) {
        const auto& r = log.at(i);
        records.push_back(
            {{"source", fmt::format("{}.{}.{}", r.source.network, r.source.node, r.source.unit)},
             {"command", fmt::format("{:02X}{:02X}", r.command.main, r.command.sub)},
             {"time",
              fmt::format("20{:02}-{:02}-{:02} {:02}:{:02}:{:02}", r.time.year, r.time.month,
                          r.time.day, r.time.hour, r.time.minute, r.time.second)}});
    }
    return records;
}

}  // namespace

Json errors_object(const server::ControlTarget& target) {
    const Json status = server::handle_control_request(*target.plc, Json{{"cmd", "status"}});
    return Json{{"errors", status["status"]["errors"]}, {"error_log", error_log(target)}};
}

Json events_object(const server::ControlTarget& target) {
    return Json{{"access_log", access_log(target)}};
}

Json status_object(const WebContext& context, const server::ControlTarget& target,
                   std::chrono::system_clock::time_point now) {
    Json answer = server::handle_control_request(*target.plc, Json{{"cmd", "status"}});
    Json status = std::move(answer["status"]);
    if (!target.name.empty()) status["plc"] = target.name;
    const auto& p = target.plc->network_write_protection_setting();
    Json nodes = Json::array();
    for (const auto& n : p.nodes)
        nodes.push_back(fmt::format("{}.{}", n.network, n.node));
    status["protections"] = {{"network_write", target.plc->network_write_protection()},
                             {"network_write_nodes", nodes},
                             {"um_read", target.plc->um_read_protection()},
                             {"dip_write", target.plc->dip_write_protection()}};
    status["faults"] = {{"battery_error", target.plc->errors().battery_low()},
                        {"errors", status["errors"]}};
    // The control status is built once (above); the logs are read on their own.
    status["error_log"] = error_log(target);
    status["access_log"] = access_log(target);
    status["connections"] = Json::array();
    status["udp_peers"] = Json::array();
    add_cpu_facts(*target.plc, status, now);
    if (context.network_status) context.network_status(target, status);
    // The page's Scenario panel: what `finsd ctl scenario status` answers.
    if (target.scenario != nullptr)
        status["scenario"] = server::handle_scenario_request(
            target.scenario, Json{{"cmd", "scenario"}, {"action", "status"}})["scenario"];
    return status;
}

void handle_request(WebContext& context, std::string_view method, std::string_view target,
                    std::string_view body, const std::function<void(HttpAnswer)>& done) {
    const auto q = parse_target(target);
    if (!q) return done(error_answer(400, "the request target is not a path"));
    const std::string& path = q->path;
    const bool get = method == "GET" || method == "HEAD";
    const auto only = [&](std::string_view allowed) {
        done(error_answer(405, fmt::format("{} takes {} only", path, allowed)));
    };
    if (path == "/api/read") {
        if (!get) return only("GET");
        return done(read_route(context, *q));
    }
    if (path == "/api/write") {
        if (method != "POST") return only("POST");
        return done(write_route(context, body));
    }
    if (path == "/api/control") {
        if (method != "POST") return only("POST");
        return control_route(context, body, done);
    }
    if (path == "/api/status") {
        if (!get) return only("GET");
        HttpAnswer error;
        const auto* t = target_of(context, plc_param(*q), error);
        if (t == nullptr) return done(error);
        return done(json_answer(200, status_object(context, *t, std::chrono::system_clock::now())));
    }
    if (path == "/api/scenario") {
        if (!get) return only("GET");
        return done(scenario_route(context, *q));
    }
    if (path == "/api/plcs") {
        if (!get) return only("GET");
        ListingRange range;
        if (auto bad = parse_listing_range(q->find("offset"), q->find("limit"), range))
            return done(std::move(*bad));
        return list_plcs(context, range, done);
    }
    if (path == "/metrics" && context.metrics) {
        if (!get) return only("GET");
        return done(HttpAnswer{200, "text/plain; version=0.0.4; charset=utf-8", context.metrics()});
    }
    const std::string_view name = path == "/" ? "index.html" : std::string_view(path).substr(1);
    if (const Asset* asset = path.empty() ? nullptr : find_asset(name)) {
        if (!get) return only("GET");
        return done(HttpAnswer{200, content_type_of(asset->name), std::string(asset->body)});
    }
    return done(error_answer(404, fmt::format("no such resource: {}", path)));
}

}  // namespace fins::web
