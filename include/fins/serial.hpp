// Serial line settings of a Host Link port (W342 3-5; the CS/CJ built-in RS-232C port's
// Host Link defaults: 9,600 bit/s, 7 data bits, even parity, 2 stop bits).
#pragma once

#include <cstdint>
#include <string>

namespace fins {

struct SerialSettings {
    std::string device;  // e.g. /dev/ttyUSB0
    unsigned baud = 9600;
    enum class Parity : std::uint8_t { none, even, odd } parity = Parity::even;
    unsigned data_bits = 7;  // 7 or 8
    unsigned stop_bits = 2;  // 1 or 2

    // Bits on the line per character: start + data + parity + stop (11 for 7E2).
    [[nodiscard]] unsigned bits_per_character() const noexcept {
        return 1 + data_bits + (parity == Parity::none ? 0u : 1u) + stop_bits;
    }
};

}  // namespace fins
