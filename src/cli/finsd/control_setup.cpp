// The control socket's path and start (contract in control_setup.hpp).
#include "cli/finsd/control_setup.hpp"

#include <unistd.h>

#include <cstdlib>
#include <utility>

#include <spdlog/spdlog.h>

namespace fins::cli {

namespace {

std::optional<std::filesystem::path> from_environment(const char* name) {
    const char* value = std::getenv(name);
    if (value == nullptr || *value == '\0') return std::nullopt;
    return std::filesystem::path(value);
}

}  // namespace

std::filesystem::path default_control_socket() {
    if (auto p = from_environment("FINSD_SOCKET")) return *p;
    if (::geteuid() != 0)
        if (auto dir = from_environment("XDG_RUNTIME_DIR")) return *dir / "finsd.sock";
    return "/run/finsd/finsd.sock";
}

ControlStart start_control(asio::io_context& io, std::vector<server::ControlTarget> targets,
                           const std::optional<std::filesystem::path>& configured) {
    ControlStart out;
    const bool chosen = configured.has_value() || from_environment("FINSD_SOCKET").has_value();
    out.path = configured ? *configured : default_control_socket();
    auto started = server::ControlServer::start(io, std::move(targets), out.path);
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
    // The default place: a second finsd, or no /run/finsd, is no reason to stop.
    spdlog::info(
        "finsd: no control channel: default socket {}: {} (give one with --control PATH or "
        "FINSD_SOCKET)",
        out.path.string(), why);
    out.path.clear();
    return out;
}

}  // namespace fins::cli
