// finsd's serial ports (issue 9): `--serial NAME=DEVICE[,KEY=VALUE...]` (repeatable) and
// the [serial] table of the configuration file, parsed into SerialPortConfig.
//
//   NAME    cpu        the CPU Unit's built-in port (Host Link slave)
//           scuN.P     port P (1 or 2) of the Serial Communications Unit with unit
//                      number N (0-F)
//           board.P    port P (1 or 2) of the Serial Communications Board
//   KEYS    baud, parity, data, stop (transport/serial_options.hpp; Host Link defaults
//           9600 7E2), unit (Host Link unit number 0-31, default 0), mode (cpu:
//           "hostlink"; scu/board: "gateway" by default, or "hostlink"), timeout
//           (seconds, 0.1-25.5, default 1: the Serial Gateway response timeout, W336).
//
// In the file, each port is a string with the same syntax after "NAME=", or a table:
//   [serial]
//   cpu = "/dev/ttyUSB0,baud=19200"
//   [serial."scu0.1"]
//   device = "/dev/ttyUSB1"
//   baud = 115200
//   timeout = 2.5
// A --serial flag replaces the file's port of the same name. Errors name the flag or the
// file position: "--serial scu16.1=/dev/x: unit number 16: 0-F".
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>
#include <tl/expected.hpp>

#include "fins/serial.hpp"

namespace fins::finsd {

// The Serial Gateway response timeout (W336 6-6-2; W342 5-3-46 .. 5-3-48 name none). A
// real Serial Communications Unit waits 5 s by default, but a FINS client gives up first:
// `fins` and the NX SendCmd instruction wait 2 s (W596 p. 3-16: timeout 0 = 2.0 s), so a
// missing slave would look like "no answer" instead of the port's 0205. 1 s answers
// 0205 within their default with room for the round trip, and leaves a Modbus slave
// (answering in tens of milliseconds) ample time.
inline constexpr double default_serial_timeout = 1.0;
inline constexpr double min_serial_timeout = 0.1;
inline constexpr double max_serial_timeout = 25.5;

struct SerialPortConfig {
    enum class Kind { cpu, scu, board };
    std::string name;  // as written: "cpu", "scu0.1", "board.2"
    Kind kind = Kind::cpu;
    unsigned unit_number = 0;  // N of scuN.P, 0-15
    unsigned port = 0;         // P of scuN.P / board.P: 1 or 2; 0 for cpu
    SerialSettings line;
    unsigned host_link_unit = 0;  // unit=
    std::string mode;             // "hostlink" or "gateway"
    double timeout_seconds = default_serial_timeout;
    // network=: the FINS network of the Host Link PLCs behind a gateway port (W342 5-1-1,
    // a routing table naming the serial path); none: the port's unit address.
    std::optional<unsigned> network;
    std::string where;  // "--serial" or "file:line:column", for messages
};

// "cpu", "scuN.P", "board.P" into kind, unit_number, port (and the default mode).
tl::expected<SerialPortConfig, std::string> parse_serial_name(std::string_view name);
// A whole --serial value: "NAME=DEVICE[,KEY=VALUE...]".
tl::expected<SerialPortConfig, std::string> parse_serial_option(std::string_view text);
// The [serial] table; `source` names the file in messages. Appends to `ports`.
tl::expected<void, std::string> load_serial_table(const toml::node& node, std::string_view source,
                                                  std::vector<SerialPortConfig>& ports);
// The --serial flags onto the file's ports (a flag replaces the port of its name; the
// same name twice among the flags is an error).
tl::expected<void, std::string> apply_serial_flags(const std::vector<std::string>& flags,
                                                   std::vector<SerialPortConfig>& ports);
// Puts `port` in `ports`, replacing the one of the same name.
void set_serial_port(std::vector<SerialPortConfig>& ports, SerialPortConfig port);
// Cross checks: cpu ports serve Host Link only; one port per name and per device.
tl::expected<void, std::string> validate_serial(const std::vector<SerialPortConfig>& ports);

}  // namespace fins::finsd
