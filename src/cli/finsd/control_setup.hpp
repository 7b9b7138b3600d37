// Where finsd's control channel listens and where `finsd ctl` looks for it (issue 18
// newcomer 6), and starting it for a single node or a plant.
//
// One rule for both programs, first match wins:
//   1. --control PATH (finsd) / --socket PATH (finsd ctl), or `control` in the config;
//   2. $FINSD_SOCKET;
//   3. $XDG_RUNTIME_DIR/finsd.sock, for a user who is not root;
//   4. /run/finsd/finsd.sock (root, and the packaged service: RuntimeDirectory=finsd).
// A socket finsd cannot open at a path given by 1 or 2 stops it (exit 3); at the default
// (3, 4) finsd says why and runs without a control channel (another finsd may hold it,
// or /run/finsd may not exist).
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <boost/asio/io_context.hpp>

#include "server/control/control.hpp"
#include "transport/asio.hpp"

namespace fins::cli {

// The socket path of rules 2-4 (the environment is read at each call).
std::filesystem::path default_control_socket();

// What main() does with the outcome: serve with `server` (maybe none), or exit `exit_code`
// after printing `error`.
struct ControlStart {
    std::unique_ptr<server::ControlServer> server;
    std::filesystem::path path;
    int exit_code = -1;  // -1: go on
    std::string error;
};

// Starts the channel for `targets` at `configured` (rule 1) or by rules 2-4.
ControlStart start_control(asio::io_context& io, std::vector<server::ControlTarget> targets,
                           const std::optional<std::filesystem::path>& configured);

}  // namespace fins::cli
