#include "finsd/serial_ports.hpp"

#include <fmt/format.h>

namespace fins::finsd {

tl::expected<void, std::string> start_serial_ports(asio::io_context& io,
                                                   server::Dispatcher& dispatcher,
                                                   const std::vector<SerialPortConfig>& ports,
                                                   SerialPorts& out) {
    for (const auto& p : ports) {
        if (p.mode == "gateway") continue;  // a Serial Gateway port: serial_gateway_setup.cpp
        if (p.mode != "hostlink")
            return tl::unexpected(
                fmt::format("{}: serial port {}: mode '{}' is not served by this build (hostlink "
                            "and gateway are)",
                            p.where, p.name, p.mode));
        server::SerialSessionOptions o;
        o.name = p.name;
        o.line = p.line;
        o.unit = static_cast<std::uint8_t>(p.host_link_unit);
        auto session = std::make_shared<server::SerialSession>(io, dispatcher, std::move(o));
        session->start();
        out.host_link.push_back(std::move(session));
    }
    return {};
}

}  // namespace fins::finsd
