// SerialPorts: lookups over the configured gateway ports (see serial_ports.hpp).
#include "server/serial/serial_ports.hpp"

namespace fins::server {

SerialGatewayPort* SerialPorts::port(std::uint8_t unit_address) const noexcept {
    for (const auto& p : ports_)
        if (p->config().unit_address == unit_address) return p.get();
    return nullptr;
}

SerialGatewayPort* SerialPorts::host_link_port(std::uint8_t network) const noexcept {
    for (const auto& p : ports_)
        if (p->config().host_link_network() == network) return p.get();
    return nullptr;
}

void SerialPorts::close_all() {
    for (const auto& p : ports_)
        p->close();
}

}  // namespace fins::server
