// (Scaffolding: implemented by the issue-3 owner of errors/messages.)
#include "server/control.hpp"

namespace fins::server {

struct ControlServer::Impl {};

Result<std::unique_ptr<ControlServer>> ControlServer::start(asio::io_context&, plc::Plc&,
                                                            const std::filesystem::path&) {
    return Unexpected(std::make_error_code(std::errc::function_not_supported));
}

ControlServer::ControlServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ControlServer::~ControlServer() = default;
void ControlServer::stop() {}

}  // namespace fins::server
