// finsd's local control channel: what an engineer changes at run time that no FINS
// command can (inject a battery error, raise FAL/FALS, set MSG texts, switch the network
// write protection, ...). A Unix-domain stream socket; one JSON request per line, one
// JSON answer per line. Runs on the server's io_context, so it touches the Plc on the
// same thread as the FINS sessions.
#pragma once

#include <filesystem>
#include <memory>

#include <asio/io_context.hpp>

#include "fins/error.hpp"

namespace fins::plc {
class Plc;
}

namespace fins::server {

class NetworkInstructions;
class InstructionSchedule;

class ControlServer {
  public:
    // Listens on `socket_path` (an existing stale socket file is replaced). With
    // `instructions`, the send / recv / sendcmd verbs run on that node's engine
    // (control_instructions.hpp).
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
