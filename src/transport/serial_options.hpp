// The serial port option string shared by `fins --serial` and `finsd --serial`:
//   DEVICE[,baud=9600][,parity=even][,data=7][,stop=2][,unit=0][,mode=NAME][,timeout=S]
// Host Link defaults (W342 3-5, the CPU Unit's built-in port): 9,600 bit/s, 7 data
// bits, even parity, 2 stop bits. Every error is one line naming the key:
//   "baud '9601': not one of 300, 600, ..., 230400".
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <tl/expected.hpp>

#include "fins/serial.hpp"

namespace fins::transport {

// What a spec may carry besides the line settings.
struct SerialSpec {
    SerialSettings line;
    std::optional<unsigned> unit;           // Host Link unit number 0-31
    std::optional<std::string> mode;        // finsd ports: "hostlink", "gateway"
    std::optional<double> timeout_seconds;  // finsd gateway ports: response timeout
    std::optional<unsigned> network;        // finsd gateway ports: FINS network behind
};

enum class SerialKeys {
    line,  // baud, parity, data, stop (fins --serial: the unit is --unit)
    port,  // also unit, mode, timeout, network (finsd --serial)
};

// The device the error messages give as an example: a COM port on Windows.
#ifdef _WIN32
inline constexpr std::string_view example_serial_device = "COM3";
#else
inline constexpr std::string_view example_serial_device = "/dev/ttyUSB0";
#endif

// Baud rates accepted (the CS/CJ serial ports' 300 .. 230,400 bit/s).
bool valid_baud(unsigned baud) noexcept;

tl::expected<SerialSpec, std::string> parse_serial_spec(std::string_view text, SerialKeys keys);
// One key=value onto `spec` (also used by finsd's [serial] tables). Error: the message.
std::optional<std::string> apply_serial_key(SerialSpec& spec, std::string_view key,
                                            std::string_view value, SerialKeys keys);
// "/dev/ttyUSB0 9600 7E2".
std::string describe_serial(const SerialSettings& line);

}  // namespace fins::transport
