// finsd's serial ports (issue 9): --serial NAME=DEVICE[,...] and the [serial] table,
// parsed directly (finsd/config_serial.hpp), no processes.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finsd/config.hpp"

namespace fins::finsd {
namespace {

TEST(FinsdSerialConfig, W342_3_5_CpuPortDefaultsToHostLink9600_7E2Unit0) {
    auto p = parse_serial_option("cpu=/dev/ttyUSB0");
    ASSERT_TRUE(p) << p.error();
    EXPECT_EQ(p->kind, SerialPortConfig::Kind::cpu);
    EXPECT_EQ(p->mode, "hostlink");
    EXPECT_EQ(p->host_link_unit, 0u);
    EXPECT_EQ(p->line.device, "/dev/ttyUSB0");
    EXPECT_EQ(p->line.baud, 9600u);
    EXPECT_EQ(p->line.data_bits, 7u);
    EXPECT_EQ(p->line.parity, SerialSettings::Parity::even);
    EXPECT_EQ(p->line.stop_bits, 2u);
    EXPECT_DOUBLE_EQ(p->timeout_seconds, default_serial_timeout);
}

TEST(FinsdSerialConfig, UnitAndBoardPortNames) {
    auto p = parse_serial_option("scuF.2=/dev/pts/4,mode=gateway,timeout=2.5,baud=115200,unit=3");
    ASSERT_TRUE(p) << p.error();
    EXPECT_EQ(p->kind, SerialPortConfig::Kind::scu);
    EXPECT_EQ(p->unit_number, 15u);
    EXPECT_EQ(p->port, 2u);
    EXPECT_EQ(p->mode, "gateway");
    EXPECT_DOUBLE_EQ(p->timeout_seconds, 2.5);
    EXPECT_EQ(p->line.baud, 115200u);
    EXPECT_EQ(p->host_link_unit, 3u);
    p = parse_serial_option("scu0.1=/dev/x");
    ASSERT_TRUE(p);
    EXPECT_EQ(p->mode, "gateway");  // a unit's port defaults to the Serial Gateway
    p = parse_serial_option("board.1=/dev/x,mode=hostlink");
    ASSERT_TRUE(p);
    EXPECT_EQ(p->kind, SerialPortConfig::Kind::board);
    EXPECT_EQ(p->port, 1u);
    EXPECT_EQ(p->mode, "hostlink");
}

TEST(FinsdSerialConfig, ErrorsNameTheFlag) {
    auto error = [](std::string_view text) {
        auto p = parse_serial_option(text);
        EXPECT_FALSE(p) << text;
        return p ? std::string{} : p.error();
    };
    EXPECT_EQ(error("/dev/ttyUSB0"),
              "--serial /dev/ttyUSB0: not NAME=DEVICE[,baud=...] (e.g. cpu=/dev/ttyUSB0,unit=0)");
    EXPECT_EQ(error("scu10.1=/dev/x"),
              "--serial scu10.1=/dev/x: port name 'scu10.1': unit number 10 is over F");
    EXPECT_EQ(error("scu1.3=/dev/x"),
              "--serial scu1.3=/dev/x: port name 'scu1.3': not cpu, scuN.P (N 0-F, P 1 or 2) or "
              "board.P");
    EXPECT_EQ(error("cpu=/dev/x,unit=32"),
              "--serial cpu=/dev/x,unit=32: unit '32': Host Link unit numbers are 0-31");
    EXPECT_EQ(error("cpu=/dev/x,mode=modbus"),
              "--serial cpu=/dev/x,mode=modbus: mode 'modbus': not hostlink or gateway");
    EXPECT_EQ(error("scu0.1=/dev/x,timeout=30"),
              "--serial scu0.1=/dev/x,timeout=30: timeout '30': seconds, 0.1-25.5 (W336)");
    EXPECT_EQ(error("cpu="), "--serial cpu=: no serial device (e.g. /dev/ttyUSB0,baud=9600)");
    EXPECT_EQ(error("scu0.1=/dev/x,network=128"),
              "--serial scu0.1=/dev/x,network=128: network '128': FINS networks are 1-127");
    EXPECT_EQ(error("scu0.1=/dev/x,network=0"),
              "--serial scu0.1=/dev/x,network=0: network '0': FINS networks are 1-127");
}

TEST(FinsdSerialConfig, FileTableAndFlagsOverrideByName) {
    Settings s;
    auto r = load_config_text(
        "[serial]\n"
        "cpu = \"/dev/ttyS0,baud=19200,unit=5\"\n"
        "[serial.\"scu0.1\"]\n"
        "device = \"/dev/ttyS1\"\n"
        "baud = 115200\n"
        "timeout = 2.5\n",
        "f.toml", s);
    ASSERT_TRUE(r) << r.error();
    ASSERT_EQ(s.serial.size(), 2u);
    EXPECT_EQ(s.serial[0].line.baud, 19200u);
    EXPECT_EQ(s.serial[0].host_link_unit, 5u);
    EXPECT_EQ(s.serial[1].line.device, "/dev/ttyS1");
    EXPECT_DOUBLE_EQ(s.serial[1].timeout_seconds, 2.5);
    Overrides o;
    o.serial = {"cpu=/dev/ttyS9"};
    ASSERT_TRUE(apply_overrides(o, s));
    ASSERT_EQ(s.serial.size(), 2u);
    EXPECT_EQ(s.serial[0].line.device, "/dev/ttyS9");
    EXPECT_EQ(s.serial[0].host_link_unit, 0u);
    EXPECT_TRUE(validate(s));

    o.serial = {"cpu=/dev/a", "cpu=/dev/b"};
    auto twice = apply_overrides(o, s);
    ASSERT_FALSE(twice);
    EXPECT_EQ(twice.error(), "--serial cpu=/dev/b: port cpu given twice");

    Settings bad;
    auto e = load_config_text("[serial]\ncpu = { baud = 9600 }\n", "f.toml", bad);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error(), "f.toml:2:1: serial.cpu: device: missing");
    e = load_config_text("[serial.cpu]\ndevice = \"/dev/x\"\nspeed = 1\n", "f.toml", bad);
    ASSERT_FALSE(e);
    EXPECT_NE(e.error().find("unknown serial option 'speed'"), std::string::npos);
}

TEST(FinsdSerialConfig, CrossChecks) {
    Settings s;
    Overrides o;
    o.serial = {"cpu=/dev/x,mode=gateway"};
    ASSERT_TRUE(apply_overrides(o, s));
    auto v = validate(s);
    ASSERT_FALSE(v);
    EXPECT_NE(v.error().find("the CPU Unit's port serves Host Link only"), std::string::npos);
    Settings t;
    o.serial = {"cpu=/dev/x", "scu1.1=/dev/x"};
    ASSERT_TRUE(apply_overrides(o, t));
    v = validate(t);
    ASSERT_FALSE(v);
    EXPECT_EQ(v.error(), "--serial: serial ports cpu and scu1.1 both use /dev/x");

    // network= (W342 5-1-1): gateway ports only, one port per network, not our own.
    const auto refused = [](std::vector<std::string> flags, std::uint8_t network = 0) {
        Settings u;
        u.network = network;
        Overrides f;
        f.serial = std::move(flags);
        EXPECT_TRUE(apply_overrides(f, u));
        const auto r = validate(u);
        return r ? std::string{} : r.error();
    };
    EXPECT_EQ(refused({"scu1.1=/dev/a,network=5"}), "");
    EXPECT_EQ(refused({"cpu=/dev/a,network=5"}),
              "--serial: serial port cpu: network=5 is for gateway ports (the Host Link PLCs "
              "behind them)");
    EXPECT_EQ(refused({"scu1.1=/dev/a,network=5", "scu1.2=/dev/b,network=5"}),
              "--serial: serial ports scu1.1 and scu1.2 both lead to network 5");
    EXPECT_EQ(refused({"scu1.1=/dev/a,network=5"}, 5),
              "--serial: serial port scu1.1: network=5 is this node's own network");
}

}  // namespace
}  // namespace fins::finsd
