// finsd's HTTP API as a plain function of (request, state): no sockets, so the unit
// tests and fuzz/fuzz_http.cpp call it directly and the Beast session (http_session.cpp)
// only reads, calls and writes. Routes and bodies: docs/web.md, docs/api/openapi.yaml.
//
//   GET  /  /<file>              the embedded page, /openapi.yaml, /chart.js
//   GET  /api/plcs               the CPU Units served [?offset=0&limit=N]
//   GET  /api/read               ?address=D100&count=3&as=uint16[&plc=NAME|NET.NODE]
//   POST /api/write              {"address","values","as"[,"plc"]}       (control on)
//   GET  /api/status             the control channel's status plus network, logs
//   GET  /api/scenario           a running scenario's tags, types, events (api_scenario.hpp)
//   POST /api/control            any control channel request object     (control on)
//   GET  /metrics                Prometheus text format
// Every error is {"error":"..."} with 400, 403, 404, 405, 413, 415, 431 or 500.
#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "web/web_context.hpp"

namespace fins::web {

struct HttpAnswer {
    unsigned status = 200;
    std::string content_type = "application/json";
    std::string body;
};

HttpAnswer json_answer(unsigned status, const nlohmann::json& body);
HttpAnswer error_answer(unsigned status, std::string_view message);

// The request fields the security rules read.
struct RequestMeta {
    std::string_view method;  // "GET", "POST", ...
    std::string_view target;  // origin-form: "/api/read?address=D0"
    std::optional<std::string_view> host;
    std::optional<std::string_view> origin;
    std::optional<std::string_view> authorization;
    bool websocket_upgrade = false;
    std::optional<std::string_view> content_type = std::nullopt;
};

// The rules every request passes before its route (nullopt: go on):
//   403 a Host header naming a host other than loopback, the bound address or an allowed
//       host (DNS rebinding); on a POST or a WebSocket upgrade, an Origin other than the
//       page's own ("http://" + the Host header, port included) or one of
//       options.allowed_origins ("null" is refused; no Origin at all passes: curl,
//       scripts); a POST without "Authorization: Bearer <token>" when a token is set.
//   415 a POST whose Content-Type is not application/json (parameters allowed), so that
//       a browser must preflight it, and finsd answers no CORS preflight.
std::optional<HttpAnswer> check_request(const WebOptions& options, const RequestMeta& meta);

// Answers one request; `done` is called exactly once: at once, or later on the io_context
// for a control request that runs a PLC-initiated instruction (send / recv / sendcmd).
void handle_request(WebContext& context, std::string_view method, std::string_view target,
                    std::string_view body, const std::function<void(HttpAnswer)>& done);

// GET /api/status's object for `target` (also the WebSocket "status" topic) at the wall
// time `now`: what changes with time (the clock offset, the cycle times) is as of `now`,
// so a caller that passes its time gets the same object for the same PLC state.
nlohmann::json status_object(const WebContext& context, const server::ControlTarget& target,
                             std::chrono::system_clock::time_point now);
// The "errors" and "events" topics: active errors and the error log; the write access log.
nlohmann::json errors_object(const server::ControlTarget& target);
nlohmann::json events_object(const server::ControlTarget& target);

}  // namespace fins::web
