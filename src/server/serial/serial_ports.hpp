// The Serial Gateway ports finsd serves (W342 5-1-1, 5-3-46 .. 5-3-48): looked up by the
// port's unit address (28 03/04/05) or by the FINS network of the Host Link slaves
// behind it (any other command, "Specifying the Destination PLC's FINS Address").
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "fins/commands/serial_gateway.hpp"
#include "server/serial/serial_gateway_port.hpp"

namespace fins::server {

// The port unit addresses (W342 5-3-46 tables) are public: `fins modbus --gateway` uses them.
using fins::board_port_unit_address;
using fins::scu_port_unit_address;

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
