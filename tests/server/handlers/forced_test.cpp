// 23 01 FORCED SET/RESET and 23 02 FORCED SET/RESET CANCEL through full frames
// (W342 5-3-44, 5-3-45), with the forced status read back through 0101 / 0104.
#include <gtest/gtest.h>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

Harness& monitor(Harness& h) {
    h.plc.set_mode(plc::OperatingMode::monitor);
    return h;
}

TEST(ForcedSetReset, W342_5_1_2_RefusedInRunMode) {
    Harness h;
    EXPECT_EQ(h.send("2301 0001 0001 30000A0D").end_code(), 0x2206);
    EXPECT_EQ(h.send("2302").end_code(), 0x2206);
    h.plc.set_mode(plc::OperatingMode::program);
    EXPECT_EQ(h.send("2301 0001 0001 30000A0D").end_code(), 0x0000);
}

TEST(ForcedSetReset, W342_5_3_44_ForceOnShowsThroughForcedStatusReads) {
    Harness h;
    monitor(h);
    ASSERT_EQ(h.send("2301 0001 0001 30000A0D").end_code(), 0x0000);
    EXPECT_EQ(h.send("0101 30000A0D 0001").data_hex(), "01");
    EXPECT_EQ(h.send("0104 70000A0D").data_hex(), "70 03");  // ON, forced
    EXPECT_EQ(h.send("0104 F0000A00").data_hex(), "F0 20 00 20 00");
    // A forced bit keeps its state against FINS writes.
    EXPECT_EQ(h.send("0102 30000A0D 0001 00").end_code(), 0x0000);
    EXPECT_EQ(h.send("0101 30000A0D 0001").data_hex(), "01");
}

TEST(ForcedSetReset, W342_5_3_44_EveryDesignation) {
    Harness h;
    monitor(h);
    // 0000 forced reset on W0.01, 0001 forced set on H2.15.
    ASSERT_EQ(h.send("2301 0002 0000 31000001 0001 3200020F").end_code(), 0x0000);
    EXPECT_EQ(h.send("0104 71000001 72000200 7200020F").data_hex(), "71 02 72 00 72 03");
    // FFFF releases and keeps the state.
    ASSERT_EQ(h.send("2301 0001 FFFF 3200020F").end_code(), 0x0000);
    EXPECT_EQ(h.send("0104 7200020F").data_hex(), "72 01");
    // 8000 turns OFF and releases; 8001 turns ON and releases.
    ASSERT_EQ(h.send("2301 0002 8000 3200020F 8001 31000001").end_code(), 0x0000);
    EXPECT_EQ(h.send("0104 7200020F 71000001").data_hex(), "72 00 71 01");
}

TEST(ForcedSetReset, W342_5_3_44_ReleaseOnAnUnforcedBitOnlySetsIt) {
    Harness h;
    monitor(h);
    ASSERT_EQ(h.send("2301 0001 8001 30000000").end_code(), 0x0000);
    EXPECT_EQ(h.send("0104 70000000").data_hex(), "70 01");  // ON, not forced
}

TEST(ForcedSetReset, W342_5_3_44_TimerAndCounterCompletionFlags) {
    Harness h;
    monitor(h);
    ASSERT_EQ(h.send("2301 0002 0001 09000500 0000 09800300").end_code(), 0x0000);
    EXPECT_EQ(h.send("0104 49000500 49800300").data_hex(), "49 03 49 02");
    EXPECT_EQ(h.send("0101 09000500 0001").data_hex(), "01");
    // CV-mode codes 00 (CIO bit) and 01 (T/C flag) name the same storage.
    ASSERT_EQ(h.send("2301 0002 0001 00000A02 FFFF 01000500").end_code(), 0x0000);
    EXPECT_EQ(h.send("0104 70000A02 49000500").data_hex(), "70 03 49 01");
}

TEST(ForcedSetReset, W342_5_3_44_ErrorsChangeNothing) {
    Harness h;
    monitor(h);
    // The second item is bad: the first is not applied either.
    EXPECT_EQ(h.send("2301 0002 0001 30000000 0002 30000001").end_code(), 0x110C);
    EXPECT_EQ(h.send("2301 0002 0001 30000000 0001 82000000").end_code(), 0x1101);
    EXPECT_EQ(h.send("2301 0002 0001 30000000 0001 30180000").end_code(), 0x1103);
    EXPECT_EQ(h.send("2301 0002 0001 30000000 0001 30000010").end_code(), 0x1103);
    EXPECT_EQ(h.send("2301 0001 0001 33000000").end_code(), 0x1101);  // AR: not forceable
    EXPECT_EQ(h.send("2301 0001 0001 B0000000").end_code(), 0x1101);  // word code
    EXPECT_EQ(h.send("0104 70000000").data_hex(), "70 00");
    EXPECT_EQ(h.send("2301 0002 0001 30000000").end_code(), 0x1003);
    EXPECT_EQ(h.send("2301 00").end_code(), 0x1002);
    EXPECT_EQ(h.send("2301 0000").end_code(), 0x0000);
}

TEST(ForcedSetResetCancel, W342_5_3_45_ReleasesEverythingKeepingTheStates) {
    Harness h;
    monitor(h);
    ASSERT_EQ(h.send("2301 0003 0001 30000000 0000 31000100 0001 09000100").end_code(), 0x0000);
    EXPECT_EQ(h.send("2302").end_code(), 0x0000);
    EXPECT_EQ(h.send("0104 70000000 71000100 49000100").data_hex(), "70 01 71 00 49 01");
    EXPECT_EQ(h.send("2302 00").end_code(), 0x1001);
}

TEST(ForcedSetReset, W342_5_1_2_NetworkWriteProtectionRefusesBoth) {
    Harness h;
    monitor(h);
    h.plc.set_network_write_protection(true);
    EXPECT_EQ(h.send("2301 0001 0001 30000000").end_code(), 0x2102);
    EXPECT_EQ(h.send("2302").end_code(), 0x2102);
}

}  // namespace
}  // namespace fins::test

namespace fins::test {
namespace {

// Every command of this group of handlers (06 01, 09 20, 0C xx, 21 xx, 23 xx) fed
// random parameter blocks of random lengths, in every mode: always one well-formed
// response, never a crash. Bounded: a fixed seed and a fixed number of frames.
TEST(DiagnosticHandlers, RandomParametersAlwaysGetAnAnswer) {
    const CommandCode codes[] = {{0x06, 0x01}, {0x09, 0x20}, {0x0C, 0x01}, {0x0C, 0x02},
                                 {0x0C, 0x03}, {0x21, 0x01}, {0x21, 0x02}, {0x21, 0x03},
                                 {0x21, 0x40}, {0x21, 0x41}, {0x23, 0x01}, {0x23, 0x02}};
    Harness h;
    std::uint32_t state = 12345;
    const auto next = [&state] {
        state = state * 1103515245U + 12345U;
        return state >> 16;
    };
    for (int i = 0; i < 20000; ++i) {
        const auto& code = codes[next() % std::size(codes)];
        h.plc.set_mode(static_cast<plc::OperatingMode>(next() % 3));
        if (next() % 50 == 0)
            h.plc.errors().raise_fal(static_cast<std::uint16_t>(1 + next() % 511), "X",
                                     h.context.now);
        std::vector<std::uint8_t> frame = request_frame("");
        frame.push_back(code.main);
        frame.push_back(code.sub);
        // Mostly short blocks, sometimes long ones up to the frame limit.
        const std::size_t length = next() % 8 == 0 ? next() % 2001 : next() % 16;
        for (std::size_t n = 0; n < length; ++n)
            frame.push_back(static_cast<std::uint8_t>(next() % 4 == 0 ? 0xFF : next()));
        if (code == CommandCode{0x23, 0x01} && length >= 2) {
            const auto items = (length - 2) / 6;  // a consistent count now and then
            if (next() % 2) {
                frame[12] = static_cast<std::uint8_t>(items >> 8);
                frame[13] = static_cast<std::uint8_t>(items);
            }
        }
        const auto reply = h.send(frame);
        ASSERT_GE(reply.frame.size(), 14u) << i;
        EXPECT_EQ(reply.command(), code) << i;
    }
}

}  // namespace
}  // namespace fins::test
