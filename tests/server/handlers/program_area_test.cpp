// 03 06 .. 03 08 PROGRAM AREA READ/WRITE/CLEAR through full request frames (W342
// 5-3-10 .. 5-3-12): every end code the manual names for them, the execution
// conditions of 5-1-2, and the choices where it is silent (program.hpp).
#include <gtest/gtest.h>

#include <string>

#include <fmt/core.h>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using plc::OperatingMode;

std::string bytes_hex(std::size_t count, std::uint8_t first = 0) {
    std::string s;
    for (std::size_t i = 0; i < count; ++i)
        s += fmt::format("{:02X}", static_cast<std::uint8_t>(first + i));
    return s;
}

std::string write_cmd(std::uint32_t address, std::size_t count, bool last, std::uint8_t first = 0,
                      std::uint16_t program = 0xFFFF) {
    return fmt::format("0307 {:04X} {:08X} {:04X} ", program, address,
                       count | (last ? 0x8000u : 0u)) +
           bytes_hex(count, first);
}

// A harness in PROGRAM mode (03 07/03 08 refuse RUN and MONITOR).
struct Stopped : Harness {
    Stopped() { plc.set_mode(OperatingMode::program); }
    [[nodiscard]] std::uint32_t um() { return plc.program().size(); }
};

TEST(ProgramAreaWrite, W342_5_3_11_WritesAndEchoesProgramNumberAddressAndCount) {
    Stopped h;
    const auto r = h.send(write_cmd(0x10, 8, true, 0xA0));
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), to_hex(hex("FFFF 00000010 8008")));
    EXPECT_EQ(h.plc.program().bytes()[0x10], 0xA0);
    EXPECT_EQ(h.plc.program().bytes()[0x17], 0xA7);
    const auto partial = h.send(write_cmd(0, 996, false));
    EXPECT_EQ(partial.data_hex(), to_hex(hex("FFFF 00000000 03E4")));
    EXPECT_TRUE(h.plc.program().download_in_progress());
}

TEST(ProgramAreaRead, W342_5_3_10_ReadsWhatWasWritten) {
    Stopped h;
    ASSERT_EQ(h.send(write_cmd(0x100, 16, true, 1)).end_code(), 0x0000);
    const auto r = h.send("0306 FFFF 00000100 0010");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), to_hex(hex("FFFF 00000100 0010" + bytes_hex(16, 1))));
    // Reading works in RUN mode too.
    h.plc.set_mode(OperatingMode::run);
    EXPECT_EQ(h.send("0306 FFFF 00000100 03E0").data().size(), 8u + 992u);
}

TEST(ProgramAreaRead, W342_5_3_10_Bit15MarksTheLastAddressAndPastTheEndIs1104) {
    Stopped h;
    const auto last = h.um() - 4;
    h.plc.program().bytes()[last] = 0x5A;
    auto r = h.send(fmt::format("0306 FFFF {:08X} 0004", last));
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), to_hex(hex(fmt::format("FFFF {:08X} 8004 5A000000", last))));
    r = h.send(fmt::format("0306 FFFF {:08X} 0010", last - 4));
    EXPECT_EQ(r.end_code(), 0x1104);
    EXPECT_EQ(r.data_hex(),
              to_hex(hex(fmt::format("FFFF {:08X} 8008 00000000 5A000000", last - 4))));
    EXPECT_EQ(h.send(fmt::format("0306 FFFF {:08X} 0004", h.um())).end_code(), 0x1103);
}

TEST(ProgramAreaRead, W342_5_3_10_ParameterErrors) {
    Stopped h;
    EXPECT_EQ(h.send("0306 0000 00000000 0004").end_code(), 0x1106);
    EXPECT_EQ(h.send("0306 FFFF 00000000 8004").end_code(), 0x110C);
    EXPECT_EQ(h.send("0306 FFFF 00000002 0004").end_code(), 0x1102);
    EXPECT_EQ(h.send("0306 FFFF 00000000 0006").end_code(), 0x1102);
    EXPECT_EQ(h.send("0306 FFFF 00000000 03E4").end_code(), 0x110B);  // 996 > 992
    EXPECT_EQ(h.send("0306 FFFF 00000000 03E4").data().size(), 0u);
    EXPECT_EQ(h.send("0306 FFFF 00000000").end_code(), 0x1002);
    EXPECT_EQ(h.send("0306 FFFF 00000000 0004 00").end_code(), 0x1001);
    EXPECT_EQ(h.send("0306 FFFF 00000000 0000").end_code(), 0x0000);
}

TEST(ProgramAreaRead, W342_5_3_10_ProtectionAnswers2002) {
    Stopped h;
    h.plc.set_um_read_protection(true);  // the execution-conditions table
    EXPECT_EQ(h.send("0306 FFFF 00000000 0004").end_code(), 0x2002);
    h.plc.set_um_read_protection(false);
    // "Prohibit from saving into a memory card, and transferring program from PLC".
    h.plc.program().set_prohibit_transfer(true);
    EXPECT_EQ(h.send("0306 FFFF 00000000 0004").end_code(), 0x2002);
    // DIP switch write protection does not stop reading.
    h.plc.program().set_prohibit_transfer(false);
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(h.send("0306 FFFF 00000000 0004").end_code(), 0x0000);
}

TEST(ProgramAreaWrite, W342_5_3_11_ParameterErrors) {
    Stopped h;
    EXPECT_EQ(h.send(write_cmd(0, 4, true, 0, 0x0001)).end_code(), 0x1106);
    EXPECT_EQ(h.send(write_cmd(0, 1000, true)).end_code(), 0x1001);
    EXPECT_EQ(h.send(write_cmd(2, 4, true)).end_code(), 0x1102);
    EXPECT_EQ(h.send(write_cmd(0, 6, true)).end_code(), 0x1102);
    EXPECT_EQ(h.send(write_cmd(h.um(), 4, true)).end_code(), 0x1103);
    EXPECT_EQ(h.send(write_cmd(h.um() - 4, 8, true)).end_code(), 0x1104);
    EXPECT_EQ(h.send("0307 FFFF 00000000 8008 01020304").end_code(), 0x1003);
    EXPECT_EQ(h.send("0307 FFFF 00000000 80").end_code(), 0x1002);
    EXPECT_EQ(h.plc.program().bytes()[0], 0);
}

TEST(ProgramAreaWrite, W342_5_3_11_OnlyInProgramModeAndUnprotected) {
    Stopped h;
    h.plc.set_mode(OperatingMode::run);
    EXPECT_EQ(h.send(write_cmd(0, 4, true)).end_code(), 0x2206);
    h.plc.set_mode(OperatingMode::monitor);
    EXPECT_EQ(h.send(write_cmd(0, 4, true)).end_code(), 0x2205);
    h.plc.set_mode(OperatingMode::program);
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(h.send(write_cmd(0, 4, true)).end_code(), 0x2101);
    h.plc.set_dip_write_protection(false);
    h.plc.set_um_read_protection(true);  // writing a read-protected UM is allowed
    EXPECT_EQ(h.send(write_cmd(0, 4, true)).end_code(), 0x0000);
    // "Prohibit from overwriting to a protected program": 2102.
    h.plc.program().set_prohibit_overwrite(true);
    EXPECT_EQ(h.send(write_cmd(0, 4, true)).end_code(), 0x2102);
    h.plc.program().set_prohibit_overwrite(false);
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(h.send(write_cmd(0, 4, true)).end_code(), 0x3001);
}

TEST(ProgramAreaClear, W342_5_3_12_ClearsTheUmAndSetsUpTheTasks) {
    Stopped h;
    h.plc.program().bytes()[40] = 0x77;
    EXPECT_EQ(h.send("0308 FFFF 10").end_code(), 0x0000);
    EXPECT_EQ(h.plc.program().bytes()[40], 0);
    EXPECT_TRUE(h.plc.program().interrupt_tasks());
    EXPECT_EQ(h.send("0308 FFFF 00").end_code(), 0x0000);
    EXPECT_FALSE(h.plc.program().interrupt_tasks());
}

TEST(ProgramAreaClear, W342_5_3_12_ClearingAReadProtectedProgramClearsTheProtection) {
    Stopped h;
    h.plc.set_um_read_protection(true);
    h.plc.program().set_prohibit_transfer(true);
    EXPECT_EQ(h.send("0308 FFFF 00").end_code(), 0x0000);
    EXPECT_FALSE(h.plc.um_read_protection());
    EXPECT_FALSE(h.plc.program().prohibit_transfer());
    EXPECT_EQ(h.send("0306 FFFF 00000000 0004").end_code(), 0x0000);
}

TEST(ProgramAreaClear, W342_5_3_12_ErrorsAndConditions) {
    Stopped h;
    EXPECT_EQ(h.send("0308 0000 00").end_code(), 0x1106);
    EXPECT_EQ(h.send("0308 FFFF 01").end_code(), 0x110C);
    EXPECT_EQ(h.send("0308 FFFF").end_code(), 0x1002);
    EXPECT_EQ(h.send("0308 FFFF 00 00").end_code(), 0x1001);
    h.plc.program().set_prohibit_overwrite(true);
    EXPECT_EQ(h.send("0308 FFFF 00").end_code(), 0x2102);
    h.plc.program().set_prohibit_overwrite(false);
    h.plc.set_mode(OperatingMode::run);
    EXPECT_EQ(h.send("0308 FFFF 00").end_code(), 0x2206);
    h.plc.set_mode(OperatingMode::monitor);
    EXPECT_EQ(h.send("0308 FFFF 00").end_code(), 0x2205);
    h.plc.set_mode(OperatingMode::program);
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(h.send("0308 FFFF 00").end_code(), 0x2101);
}

TEST(ProgramAreaRead, W342_5_3_10_ReadingTheWholeUmIn992ByteBlocksEndsOnBit15) {
    Stopped h;
    std::uint32_t address = 0;
    bool last = false;
    std::size_t blocks = 0;
    // CJ2H: 800 K words = 1,638,400 bytes = 1,652 blocks of 992 bytes.
    for (; !last && blocks < 2000; ++blocks) {
        const auto r = h.send(fmt::format("0306 FFFF {:08X} 03E0", address));
        ASSERT_TRUE(r.end_code() == 0x0000 || r.end_code() == 0x1104) << r.end_code();
        const auto d = r.data();
        ASSERT_GE(d.size(), 8u);
        const auto count = static_cast<std::uint16_t>((d[6] << 8) | d[7]);
        last = (count & 0x8000) != 0;
        address += count & 0x7FFFu;
    }
    EXPECT_TRUE(last);
    EXPECT_EQ(address, h.um());
}

}  // namespace
}  // namespace fins::test
