// Starting finsd's HTTP/WebSocket front (docs/web.md) for a single node or a plant, on
// finsd's io_context: the token file is read here, the CPU Units are the control
// channel's targets, and the server's knowledge (connections, routes) is added to
// /api/plcs, /api/status and /metrics through WebContext's hooks.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "finsd/config_http.hpp"
#include "server/control/control.hpp"
#include "web/http_server.hpp"

namespace fins::server {
class Server;
class Plant;
}  // namespace fins::server

namespace fins::finsd {

struct WebStart {
    std::unique_ptr<web::HttpServer> server;  // null: no --http
    int exit_code = -1;                       // -1: go on; else exit with `error`
    std::string error;
};

// `servers[i]` serves `targets[i]` (its first Ethernet unit in a plant); `plant` when
// there is one (routes and relays).
WebStart start_web(boost::asio::io_context& io, const HttpSettings& http,
                   std::vector<server::ControlTarget> targets,
                   std::vector<const server::Server*> servers, server::Plant* plant = nullptr);

}  // namespace fins::finsd
