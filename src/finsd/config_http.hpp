// finsd's HTTP/WebSocket front in the configuration: the [http] table and the
// --http / --http-control / --http-token-file flags (flags override the file).
//
//   [http]
//   listen = "127.0.0.1:8080"        # ADDRESS:PORT ([::1]:8080 for IPv6); absent: no HTTP
//   control = false                  # POST /api/write and /api/control
//   token_file = "/etc/finsd/token"  # bearer token for POSTs; required when `listen` is
//                                    # not a loopback address and control is on
//   allowed_hosts = ["plc-sim.lan"]  # host names the Host header may carry (besides
//                                    # localhost and IP addresses)
//   allowed_origins = ["https://scada.lan"]  # origins besides the page's own that may
//                                    # POST and open /ws (docs/web.md "Security rules")
//   max_connections = 64
//   websocket_idle_timeout = 60      # seconds: a silent WebSocket client is pinged after
//                                    # half of it and closed when nothing came by its end
//
// Parsing and checks only (no sockets, no files); finsd/web_setup reads the token
// file and starts the server (docs/web.md).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <toml++/toml.h>
#include <CLI/App.hpp>
#include <tl/expected.hpp>

namespace fins::finsd {

struct HttpSettings {
    std::optional<std::string> listen;  // ADDRESS:PORT
    bool control = false;
    std::optional<std::filesystem::path> token_file;
    std::vector<std::string> allowed_hosts;
    std::vector<std::string> allowed_origins;
    std::size_t max_connections = 64;
    std::chrono::milliseconds websocket_idle_timeout{std::chrono::seconds(60)};
};

// "127.0.0.1:8080", "[::1]:0", "0.0.0.0:80" -> (address, port); an error sentence else.
tl::expected<std::pair<std::string, std::uint16_t>, std::string> parse_http_listen(
    std::string_view text);

// True for 127.0.0.0/8 and ::1.
bool loopback_address(std::string_view address);

// The [http] table onto `http`; errors name file:line:column and the key.
tl::expected<void, std::string> load_http_table(const toml::node& node, std::string_view source,
                                                HttpSettings& http);

// The command-line flags, registered on `app` (main.cpp's configure()); apply_http_flags()
// puts the given ones over the file's [http] after the file is loaded.
struct HttpFlags {
    std::string listen;
    std::string token_file;
    bool control = false;
    CLI::Option* listen_option = nullptr;
    CLI::Option* token_option = nullptr;
    CLI::Option* control_option = nullptr;
};
void add_http_flags(CLI::App& app, HttpFlags& flags);
void apply_http_flags(const HttpFlags& flags, HttpSettings& http);

// Cross-field rules: a valid `listen`; beyond loopback with control on, a token file.
tl::expected<void, std::string> check_http(const HttpSettings& http);

}  // namespace fins::finsd
