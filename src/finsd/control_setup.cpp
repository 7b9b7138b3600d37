// The control socket's path and start (contract in control_setup.hpp).
#include "finsd/control_setup.hpp"

#include <sys/stat.h>
#ifndef _WIN32
#include <unistd.h>
#endif

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "web/subscriptions.hpp"

namespace fins::finsd {

namespace {

std::optional<std::filesystem::path> from_environment(const char* name) {
    const char* value = std::getenv(name);
    if (value == nullptr || *value == '\0') return std::nullopt;
    return std::filesystem::path(value);
}

#ifdef _WIN32
// Windows: the user's own %LOCALAPPDATA%\finskit (its ACL admits the user alone), the
// channel file there as the socket is in Linux's /tmp/finsd-UID.
std::pair<std::filesystem::path, mode_t> own_directory() {
    const auto local = from_environment("LOCALAPPDATA");
    return {(local ? *local : std::filesystem::temp_directory_path()) / "finskit", 0700};
}
uid_t effective_user() {
    return 0;
}
#else
const std::filesystem::path root_directory = "/run/finsd";

std::filesystem::path user_directory() {
    return fmt::format("/tmp/finsd-{}", ::geteuid());
}

// Rule 4 or 5: the directory and the mode finsd creates it with.
std::pair<std::filesystem::path, mode_t> own_directory() {
    if (::geteuid() == 0) return {root_directory, 0755};
    return {user_directory(), 0700};
}
uid_t effective_user() {
    return ::geteuid();
}
#endif

}  // namespace

std::filesystem::path default_control_socket() {
    if (auto p = from_environment("FINSD_SOCKET")) return *p;
    if (auto dir = from_environment("XDG_RUNTIME_DIR")) return *dir / "finsd.sock";
    return own_directory().first / "finsd.sock";
}

std::vector<std::filesystem::path> default_control_sockets() {
    if (auto p = from_environment("FINSD_SOCKET")) return {*p};
    std::vector<std::filesystem::path> out;
    if (auto dir = from_environment("XDG_RUNTIME_DIR")) out.push_back(*dir / "finsd.sock");
    out.push_back(own_directory().first / "finsd.sock");
    return out;
}

#ifdef _WIN32
// No owner or mode bits to check: the directory's ACL (inherited from the user's profile)
// is what protects the socket. A link or junction in its place is refused.
std::string prepare_socket_directory(const std::filesystem::path& dir, mode_t, uid_t) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) return fmt::format("cannot create {}: {}", dir.string(), ec.message());
    const auto st = std::filesystem::symlink_status(dir, ec);
    if (ec) return fmt::format("{}: {}", dir.string(), ec.message());
    if (std::filesystem::is_symlink(st)) return fmt::format("{} is a symbolic link", dir.string());
    if (!std::filesystem::is_directory(st))
        return fmt::format("{} is not a directory", dir.string());
    return {};
}
#else
std::string prepare_socket_directory(const std::filesystem::path& dir, mode_t mode, uid_t owner) {
    if (::mkdir(dir.c_str(), mode) != 0 && errno != EEXIST)
        return fmt::format("cannot create {}: {}", dir.string(), std::strerror(errno));
    struct stat st {};
    if (::lstat(dir.c_str(), &st) != 0)
        return fmt::format("{}: {}", dir.string(), std::strerror(errno));
    if (S_ISLNK(st.st_mode)) return fmt::format("{} is a symbolic link", dir.string());
    if (!S_ISDIR(st.st_mode)) return fmt::format("{} is not a directory", dir.string());
    if (st.st_uid != owner)
        return fmt::format("{} is owned by uid {}, not {}", dir.string(), st.st_uid, owner);
    const mode_t others = (mode & 077) == 0 ? 077 : 022;
    if ((st.st_mode & others) != 0)
        return fmt::format("{} has mode {:04o}; {:04o} is needed", dir.string(), st.st_mode & 07777,
                           mode);
    return {};
}
#endif

std::string control_channel_hint() {
#ifdef _WIN32
    return "start finsd with a control channel: `finsd --control PATH`, then "
           "`finsd ctl --socket PATH ...` (or set FINSD_SOCKET=PATH for both); without them "
           "both use %LOCALAPPDATA%\\finskit\\finsd.sock (the channel file: port and token)";
#else
    return "start finsd with a control channel: `finsd --control PATH`, then "
           "`finsd ctl --socket PATH ...` (or set FINSD_SOCKET=PATH for both); without them "
           "both use $XDG_RUNTIME_DIR/finsd.sock, else /run/finsd/finsd.sock (root) or "
           "/tmp/finsd-UID/finsd.sock";
#endif
}

ControlStart start_control(asio::io_context& io, std::vector<server::ControlTarget> targets,
                           const std::optional<std::filesystem::path>& configured) {
    ControlStart out;
    const bool chosen = configured.has_value() || from_environment("FINSD_SOCKET").has_value();
    out.path = configured ? *configured : default_control_socket();
    if (!chosen && !from_environment("XDG_RUNTIME_DIR")) {
        const auto [dir, mode] = own_directory();
        if (const auto why = prepare_socket_directory(dir, mode, effective_user()); !why.empty()) {
            spdlog::warn(
                "finsd: no control channel: {} (give one with --control PATH or "
                "FINSD_SOCKET)",
                why);
            out.path.clear();
            return out;
        }
    }
    server::ControlOptions options;
    if (options.transport == server::ControlTransport::loopback_tcp) {
        // The loopback channel's secret (control_channel_file.hpp): the CSPRNG that names
        // the web page's sessions.
        try {
            options.token = web::new_session_id();
        } catch (const std::exception& e) {
            out.exit_code = 3;
            out.error = fmt::format("control channel: no random token: {}", e.what());
            return out;
        }
    }
    auto started = server::ControlServer::start(io, std::move(targets), out.path, options);
    if (started) {
        out.server = std::move(*started);
        spdlog::info("finsd: control channel on {}", out.path.string());
        return out;
    }
    const std::string why = started.error().message();
    if (chosen) {
        out.exit_code = 3;
        out.error = "control channel " + out.path.string() + ": " + why;
        return out;
    }
    // The default place: a second finsd is no reason to stop.
    spdlog::warn(
        "finsd: no control channel: default socket {}: {} (give one with --control PATH or "
        "FINSD_SOCKET)",
        out.path.string(), why);
    out.path.clear();
    return out;
}

}  // namespace fins::finsd
