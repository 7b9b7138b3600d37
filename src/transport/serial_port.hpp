// A serial device opened through Asio's serial_port (termios): baud rate, 7 or 8 data
// bits, no/even/odd parity, 1 or 2 stop bits, no flow control, raw mode (Asio's open
// clears the line discipline's echo, canonical mode and CR/NL translation). Used by the
// Host Link client transport and finsd's serial sessions; works on ptys (socat) too,
// where no baud rate limits the data and 7 data bits are
// refused by the kernel (the port then stays at 8 bits: Host Link text is 7-bit ASCII).
#pragma once

#include <system_error>

#include <boost/asio/io_context.hpp>
#include <boost/asio/serial_port.hpp>

#include "fins/serial.hpp"
#include "transport/asio.hpp"

namespace fins::transport {

class SerialPort {
  public:
    explicit SerialPort(asio::io_context& io) : port_(io) {}

    // Opens `line.device` and applies the settings; on failure the port stays closed.
    boost::system::error_code open(const SerialSettings& line);
    void close() noexcept;
    [[nodiscard]] bool is_open() const noexcept { return port_.is_open(); }
    // Discards what the kernel holds unread or unsent (TCIOFLUSH).
    void flush() noexcept;
    [[nodiscard]] asio::serial_port& port() noexcept { return port_; }
    // True for a pseudo-terminal (e.g. one end of a socat pair). On Windows: true for any
    // open port under Wine (asked only once the port refused 7 data bits), false otherwise.
    [[nodiscard]] bool is_pseudo_terminal() noexcept;

  private:
    asio::serial_port port_;
};

}  // namespace fins::transport
