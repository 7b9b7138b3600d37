#include "transport/serial_port.hpp"

#ifdef _WIN32
#include <windows.h>
#else
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#endif

#include <cerrno>

namespace fins::transport {
namespace {

#ifdef _WIN32
constexpr int refused_setting = ERROR_INVALID_PARAMETER;

// Wine's ntdll exports wine_get_version (Wine's documented way for a program to tell).
bool under_wine() noexcept {
    const HMODULE ntdll = ::GetModuleHandleW(L"ntdll.dll");
    return ntdll != nullptr && ::GetProcAddress(ntdll, "wine_get_version") != nullptr;
}
#else
constexpr int refused_setting = EINVAL;
#endif

}  // namespace

boost::system::error_code SerialPort::open(const SerialSettings& line) {
    close();
    boost::system::error_code ec;
    port_.open(line.device, ec);
    if (ec) return ec;
    using asio::serial_port_base;
    const auto parity = line.parity == SerialSettings::Parity::none ? serial_port_base::parity::none
                        : line.parity == SerialSettings::Parity::even
                            ? serial_port_base::parity::even
                            : serial_port_base::parity::odd;
    const auto stop =
        line.stop_bits == 2 ? serial_port_base::stop_bits::two : serial_port_base::stop_bits::one;
    port_.set_option(serial_port_base::baud_rate(line.baud), ec);
    if (!ec) {
        port_.set_option(serial_port_base::character_size(line.data_bits), ec);
        // Linux ptys (socat) refuse 7 data bits (EINVAL); they have no line, and Host Link
        // characters are 7-bit ASCII, so the 8-bit bytes of a pty carry them unchanged.
        // Under Wine a COM port mapped onto a pty gets the same refusal through
        // SetCommState (ERROR_INVALID_PARAMETER).
        if (ec.value() == refused_setting && is_pseudo_terminal()) ec.clear();
    }
    if (!ec) port_.set_option(serial_port_base::parity(parity), ec);
    if (!ec) port_.set_option(serial_port_base::stop_bits(stop), ec);
    if (!ec)
        port_.set_option(serial_port_base::flow_control(serial_port_base::flow_control::none), ec);
    if (ec) {
        close();
        return ec;
    }
    flush();
    return {};
}

bool SerialPort::is_pseudo_terminal() noexcept {
#ifdef _WIN32
    // Windows' own COM ports (and com0com's virtual pairs) take 7 data bits: no pty rule
    // to bend. Wine maps a COM port onto a Unix tty (a dosdevices symlink); a real UART
    // there takes 7 data bits too, so one that refuses them is a pty.
    return port_.is_open() && under_wine();
#else
    struct stat st {};
    if (!port_.is_open() || ::fstat(port_.native_handle(), &st) != 0) return false;
    // Unix98 pty slaves: character devices with majors 136-143 (Documentation/admin-guide/
    // devices.txt).
    const auto major_number = major(st.st_rdev);
    return S_ISCHR(st.st_mode) && major_number >= 136 && major_number <= 143;
#endif
}

void SerialPort::flush() noexcept {
    if (!port_.is_open()) return;
#ifdef _WIN32
    ::PurgeComm(port_.native_handle(), PURGE_RXCLEAR | PURGE_TXCLEAR);
#else
    ::tcflush(port_.native_handle(), TCIOFLUSH);
#endif
}

void SerialPort::close() noexcept {
    boost::system::error_code ignored;
    port_.close(ignored);
}

}  // namespace fins::transport
