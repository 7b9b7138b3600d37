// The serial option string (src/transport/serial_options.hpp) and the serial port over
// a socat pty pair.
#include <gtest/gtest.h>

#ifndef _WIN32
#include <poll.h>
#endif

#include <array>
#include <chrono>
#include <string>

#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>

#ifndef _WIN32
#include "integration/support/pty_pair.hpp"
#endif
#include "transport/asio.hpp"
#include "transport/serial_options.hpp"
#include "transport/serial_port.hpp"

namespace fins::transport {
namespace {

TEST(SerialOptions, W342_3_5_HostLinkDefaultsAre9600_7E2) {
    auto s = parse_serial_spec("/dev/ttyUSB0", SerialKeys::line);
    ASSERT_TRUE(s) << s.error();
    EXPECT_EQ(s->line.device, "/dev/ttyUSB0");
    EXPECT_EQ(s->line.baud, 9600u);
    EXPECT_EQ(s->line.parity, SerialSettings::Parity::even);
    EXPECT_EQ(s->line.data_bits, 7u);
    EXPECT_EQ(s->line.stop_bits, 2u);
    EXPECT_EQ(s->line.bits_per_character(), 11u);
    EXPECT_EQ(describe_serial(s->line), "/dev/ttyUSB0 9600 7E2");
}

TEST(SerialOptions, EveryKey) {
    auto s =
        parse_serial_spec("/dev/pts/3,baud=115200,parity=none,data=8,stop=1", SerialKeys::line);
    ASSERT_TRUE(s) << s.error();
    EXPECT_EQ(describe_serial(s->line), "/dev/pts/3 115200 8N1");
    s = parse_serial_spec("/dev/x,unit=31,mode=gateway,timeout=0.5,parity=odd", SerialKeys::port);
    ASSERT_TRUE(s) << s.error();
    EXPECT_EQ(s->unit, 31u);
    EXPECT_EQ(s->mode, "gateway");
    EXPECT_DOUBLE_EQ(s->timeout_seconds.value_or(0), 0.5);
    EXPECT_EQ(s->line.parity, SerialSettings::Parity::odd);
}

TEST(SerialOptions, ClearErrors) {
    auto error = [](std::string_view text, SerialKeys keys = SerialKeys::line) {
        auto s = parse_serial_spec(text, keys);
        EXPECT_FALSE(s) << text;
        return s ? std::string{} : s.error();
    };
#ifdef _WIN32
    const std::string no_device = "no serial device (e.g. COM3,baud=9600)";
#else
    const std::string no_device = "no serial device (e.g. /dev/ttyUSB0,baud=9600)";
#endif
    EXPECT_EQ(error(""), no_device);
    EXPECT_EQ(error(",baud=9600"), no_device);
    EXPECT_NE(error("/dev/x,baud=9601").find("baud '9601': not one of 300"), std::string::npos);
    EXPECT_EQ(error("/dev/x,data=6"), "data '6': data bits are 7 or 8");
    EXPECT_EQ(error("/dev/x,stop=3"), "stop '3': stop bits are 1 or 2");
    EXPECT_EQ(error("/dev/x,parity=mark"), "parity 'mark': not none, even or odd");
    EXPECT_EQ(error("/dev/x,baud"), "serial option 'baud' is not KEY=VALUE");
    EXPECT_EQ(error("/dev/x,unit=1"),
              "unknown serial option 'unit' (known: baud, parity, data, stop)");
    EXPECT_EQ(error("/dev/x,unit=32", SerialKeys::port),
              "unit '32': Host Link unit numbers are 0-31");
    EXPECT_EQ(error("/dev/x,timeout=0", SerialKeys::port),
              "timeout '0': seconds, more than 0 and at most 3600");
}

// Linux ptys (socat); on Windows a COM port is a device of Wine's, tested there.
#ifndef _WIN32
TEST(SerialPort, OpensAPtyWithTheLineSettingsAndMovesBytes) {
    test::PtyPair pty;
    ASSERT_TRUE(pty.ok());
    asio::io_context io;
    SerialPort a(io);
    SerialPort b(io);
    SerialSettings line;
    line.device = pty.a();
    const auto opened = a.open(line);
    ASSERT_FALSE(opened) << opened.message();
    line.device = pty.b();
    line.baud = 115200;
    line.data_bits = 8;
    line.parity = SerialSettings::Parity::none;
    ASSERT_FALSE(b.open(line));
    const std::string text = "@00FA0000000000101\r";
    asio::write(a.port(), asio::buffer(text));
    std::string got;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (got.size() < text.size() && std::chrono::steady_clock::now() < deadline) {
        pollfd p{b.port().native_handle(), POLLIN, 0};
        if (::poll(&p, 1, 100) <= 0) continue;
        std::array<char, 64> chunk{};
        got.append(chunk.data(), b.port().read_some(asio::buffer(chunk)));
    }
    EXPECT_EQ(got, text);
    SerialPort missing(io);
    line.device = "/dev/finskit-no-such-device";
    EXPECT_TRUE(missing.open(line));
    EXPECT_FALSE(missing.is_open());
}
#endif

}  // namespace
}  // namespace fins::transport
