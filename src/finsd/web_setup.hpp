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

// `units[i]` are the Ethernet units of `targets[i]`, in the configuration's order (the
// listing's udp_port and tcp_port are the first one's; connections, peers and
// fins_tcp_connections count them all); `plant` when there is one (routes and relays).
using UnitServers = std::vector<const server::Server*>;
WebStart start_web(boost::asio::io_context& io, const HttpSettings& http,
                   std::vector<server::ControlTarget> targets, std::vector<UnitServers> units,
                   server::Plant* plant = nullptr);

}  // namespace fins::finsd
