// finsd's local control channel: what an engineer changes at run time that no FINS
// command can (inject a battery error, raise FAL/FALS, set MSG texts, switch the network
// write protection, ...). One JSON request per line, one JSON answer per line, over a
// Unix-domain stream socket (Linux) or a loopback TCP connection that starts with a secret
// token line (Windows, issue 28: control_channel_file.hpp). Runs on the server's
// io_context, so it touches the Plc on the same thread as the FINS sessions.
//
// The verbs: control_requests.hpp (the PLC's state) and control_instructions.hpp
// (PLC-initiated messages). Any request may carry "plc": the CPU Unit it is for, by
// its [[plc]] name or by one of its FINS addresses "NET.NODE" (a plant); without it,
// the first CPU Unit.
//
// Connections (issue 18 item 4): at most `max_connections` clients wait for a request
// line at once; a new client is always served: when every slot is taken, the one idle
// the longest is closed. A client silent for `idle_timeout` is closed. A client whose
// instruction (send / recv / sendcmd) is in flight holds no slot (the instruction
// engine bounds those), so it can never crowd out a `status`.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "fins/error.hpp"
#include "transport/asio.hpp"

namespace fins::plc {
class Plc;
}

namespace fins::server {

class NetworkInstructions;
class InstructionSchedule;
class ScenarioControl;

// One [[schedule]] entry of a CPU Unit: the schedule that runs it (that of the unit its
// destination is reached through) and its place there.
struct ScheduleEntry {
    const InstructionSchedule* schedule = nullptr;
    std::size_t index = 0;
};

// One CPU Unit the channel drives.
struct ControlTarget {
    plc::Plc* plc = nullptr;
    std::string name;  // its [[plc]] name ("" for a single node)
    std::vector<std::pair<std::uint8_t, std::uint8_t>> addresses;  // its (network, node)s
    // With an engine, the send / recv / sendcmd verbs run on it.
    NetworkInstructions* instructions = nullptr;
    // Its [[schedule]] entries in the configuration's order, whichever unit runs each.
    std::vector<ScheduleEntry> schedule;
    ScenarioControl* scenario = nullptr;  // its running scenario, if any (control_scenario.hpp)
};

// How clients reach the channel. Unix: a Unix-domain socket at the path. Loopback: a TCP
// listener on 127.0.0.1 at an ephemeral port, announced in a channel file at the path
// (`<port> <token>`, control_channel_file.hpp); a client's first line must be the token,
// or it is closed without an answer. Windows has the loopback kind only (Wine has no
// AF_UNIX); Linux uses the Unix kind, and its tests the loopback one too.
enum class ControlTransport {
#ifndef _WIN32
    unix_socket,
#endif
    loopback_tcp,
};

#ifdef _WIN32
inline constexpr ControlTransport default_control_transport = ControlTransport::loopback_tcp;
#else
inline constexpr ControlTransport default_control_transport = ControlTransport::unix_socket;
#endif

struct ControlOptions {
    std::size_t max_connections = 16;
    std::chrono::milliseconds idle_timeout{std::chrono::seconds(60)};  // 0: never
    ControlTransport transport = default_control_transport;
    // Loopback: the secret a client sends first (at least 16 characters, no white space).
    std::string token{};
};

class ControlServer {
  public:
    // Listens on `socket_path` (Unix: an existing stale socket file is replaced; loopback:
    // the channel file, replaced when stale; see control_channel_file.hpp) for the CPU
    // Units `targets` (at least one; the first is the default). The path is removed at stop.
    static Result<std::unique_ptr<ControlServer>> start(asio::io_context& io,
                                                        std::vector<ControlTarget> targets,
                                                        const std::filesystem::path& socket_path,
                                                        ControlOptions options = {});
    // One CPU Unit.
    static Result<std::unique_ptr<ControlServer>> start(
        asio::io_context& io, plc::Plc& plc, const std::filesystem::path& socket_path,
        NetworkInstructions* instructions = nullptr, const InstructionSchedule* schedule = nullptr);
    ~ControlServer();
    ControlServer(const ControlServer&) = delete;
    ControlServer& operator=(const ControlServer&) = delete;
    void stop();

    struct Impl;

  private:
    explicit ControlServer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace fins::server
