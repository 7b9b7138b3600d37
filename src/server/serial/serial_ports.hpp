// The Serial Gateway ports finsd serves (W342 5-1-1, 5-3-46 .. 5-3-48): looked up by the
// port's unit address (28 03/04/05) or by the FINS network of the Host Link slaves
// behind it (any other command, "Specifying the Destination PLC's FINS Address").
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "server/serial/serial_gateway_port.hpp"

namespace fins::server {

// W342 5-3-46 tables: Serial Communications Unit N port 1 = 80 + 4N, port 2 = 81 + 4N
// (N = 0-F); the Board's ports E4 and E5.
constexpr std::uint8_t scu_port_unit_address(unsigned unit_number, unsigned port) noexcept {
    return static_cast<std::uint8_t>(0x80U + 4U * unit_number + (port - 1U));
}
constexpr std::uint8_t board_port_unit_address(unsigned port) noexcept {
    return static_cast<std::uint8_t>(0xE4U + (port - 1U));
}

class SerialPorts {
  public:
    void add(std::shared_ptr<SerialGatewayPort> port) { ports_.push_back(std::move(port)); }
    // The port with this unit address, or nullptr.
    [[nodiscard]] SerialGatewayPort* port(std::uint8_t unit_address) const noexcept;
    // The port whose Host Link slaves are on FINS network `network`, or nullptr.
    [[nodiscard]] SerialGatewayPort* host_link_port(std::uint8_t network) const noexcept;
    [[nodiscard]] const std::vector<std::shared_ptr<SerialGatewayPort>>& all() const noexcept {
        return ports_;
    }
    void close_all();

  private:
    std::vector<std::shared_ptr<SerialGatewayPort>> ports_;
};

}  // namespace fins::server
