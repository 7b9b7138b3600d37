// Where finsd's control channel listens and where `finsd ctl` looks for it (issue 18
// newcomer 6, issue 26 point 8), and starting it for a single node or a plant.
//
// One rule for both programs, first match wins:
//   1. --control PATH (finsd) / --socket PATH (finsd ctl), or `control` in the config;
//   2. $FINSD_SOCKET;
//   3. $XDG_RUNTIME_DIR/finsd.sock, when it is set (the user's own runtime directory,
//      root's login session included);
//   4. root: /run/finsd/finsd.sock; finsd creates /run/finsd (0755, owned by root; the
//      socket itself is 0600) as the packaged service's RuntimeDirectory=finsd does;
//   5. any other user: /tmp/finsd-UID/finsd.sock; finsd creates /tmp/finsd-UID 0700 and
//      refuses it when it is a symbolic link, owned by someone else or open to others.
// A socket finsd cannot open at a path given by 1 or 2 stops it (exit 3); at the default
// (3-5) finsd warns why and runs without a control channel (another finsd may hold it).
// `finsd ctl` without --socket/FINSD_SOCKET tries 3 then 4 or 5, the first that exists.
// Windows (docs/windows.md): the path names the loopback channel's file (`<port> <token>`,
// server/control/control_channel_file.hpp), by default %LOCALAPPDATA%\finskit\finsd.sock;
// start_control draws the token from web::new_session_id's CSPRNG.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "server/control/control.hpp"
#include "transport/asio.hpp"

namespace fins::finsd {

#ifdef _WIN32
using uid_t = unsigned;  // Windows has no user ids: the directory's ACL protects it
#endif

// The socket path finsd listens on by rules 2-5 (the environment is read at each call).
std::filesystem::path default_control_socket();

// The places `finsd ctl` looks in, in order: $FINSD_SOCKET alone when set, else rules 3-5.
std::vector<std::filesystem::path> default_control_sockets();

// Makes `dir` ready to hold a control socket: created with `mode` when missing, then it
// must be a directory (not a symbolic link) owned by `owner` that no one else may write
// to (and, for `mode` 0700, not read either). An empty string when it is; why not else.
std::string prepare_socket_directory(const std::filesystem::path& dir, mode_t mode, uid_t owner);

// The line `finsd ctl` prints after "cannot connect": how to start finsd with a channel.
std::string control_channel_hint();

// What main() does with the outcome: serve with `server` (maybe none), or exit `exit_code`
// after printing `error`.
struct ControlStart {
    std::unique_ptr<server::ControlServer> server;
    std::filesystem::path path;
    int exit_code = -1;  // -1: go on
    std::string error;
};

// Starts the channel for `targets` at `configured` (rule 1) or by rules 2-5.
ControlStart start_control(asio::io_context& io, std::vector<server::ControlTarget> targets,
                           const std::optional<std::filesystem::path>& configured);

}  // namespace fins::finsd
