// finsd's Serial Gateway ports (W342 5-1-1, 5-3-46 .. 5-3-48): the scuN.P / board.P
// entries of --serial and [serial] in mode "gateway" become server::SerialGatewayPorts,
// and their units are mounted in the profile so 05 02 CONNECTION DATA READ lists them.
//
//   scuN.P   a Serial Communications Unit with unit number N: CPU Bus Unit 10 + N
//            ("CJ1W-SCU41-V1", or "CS1W-SCU21-V1" on a CS-series profile); its ports
//            answer at unit addresses 80 + 4N (port 1) and 81 + 4N (port 2)
//   board.P  the Serial Communications Board "CS1W-SCB41-V1", an Inner Board (E1), on
//            CS-series profiles only; its ports answer at E4 and E5
// A unit number the profile already uses (the Ethernet Unit's, usually 0) is refused: a
// real PLC refuses duplicated unit numbers too.
#pragma once

#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <tl/expected.hpp>

#include "finsd/config_serial.hpp"
#include "plc/profile.hpp"
#include "server/serial/serial_ports.hpp"
#include "transport/asio.hpp"

namespace fins::finsd {

// True for the ports this file serves (scu/board in mode "gateway").
bool is_gateway_port(const SerialPortConfig& port) noexcept;

// Adds the units of the gateway ports to `profile`; an error names the clash.
tl::expected<void, std::string> mount_serial_units(const std::vector<SerialPortConfig>& ports,
                                                   plc::Profile& profile);

// The server-side configuration of one gateway port.
server::GatewayPortConfig gateway_port_config(const SerialPortConfig& port);

// Opens every gateway port into `out`. A device that cannot be opened is logged and the
// port kept: its requests answer 0205 until the device opens (finsd keeps serving, as
// it does for Host Link ports).
void open_gateway_ports(asio::io_context& io, const std::vector<SerialPortConfig>& ports,
                        server::SerialPorts& out);

}  // namespace fins::finsd
