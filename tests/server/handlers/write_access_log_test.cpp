// 21 40 / 21 41 and the dispatcher's logging of FINS write commands (W342 5-3-30,
// 5-3-31), plus the end-code flags of the error model on ordinary commands (5-1-3).
#include <gtest/gtest.h>
#include <malloc.h>

#include <chrono>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using namespace std::chrono;
const system_clock::time_point t0 = sys_days{year{2026} / November / 22} + hours{1};

FrameFields from(std::uint8_t node) {
    FrameFields f;
    f.source = NodeAddress{0x01, node, 0x00};
    return f;
}

TEST(WriteAccessLogRead, W342_5_3_30_WriteCommandsAreLoggedReadsAreNot) {
    Harness h;
    h.context.now = t0 + minutes{2} + seconds{3};
    ASSERT_EQ(h.send("0102 82000000 0001 1234").end_code(), 0x0000);
    ASSERT_EQ(h.send("0101 82000000 0001").end_code(), 0x0000);
    auto r = h.send("2140 0000 0014");
    EXPECT_EQ(r.end_code(), 0x0000);  // fewer stored than asked for: normal
    // network, node, unit, 00, command, minute second day hour year month (BCD).
    EXPECT_EQ(r.data_hex(), "00 14 00 01 00 01 01 14 00 00 01 02 02 03 22 01 26 11");
}

TEST(WriteAccessLogRead, W342_5_3_30_EveryAccessIsLoggedWhateverItsEndCode) {
    Harness h;
    ASSERT_EQ(h.send("0102 B3000000 0001 0000").end_code(), 0x2101);  // A000 is read-only
    EXPECT_EQ(h.plc.write_access_log().size(), 1u);
    EXPECT_EQ(h.plc.write_access_log().at(0).command, (CommandCode{0x01, 0x02}));
}

TEST(WriteAccessLogRead, W342_5_3_30_OneRecordPerNodeLatestCommand) {
    Harness h;
    h.send("0102 82000000 0001 0001", from(0x20));
    h.send("0102 82000000 0001 0001", from(0x21));
    h.send("0103 82000000 0001 0002", from(0x20));
    auto r = h.send("2140 0000 0014");
    EXPECT_EQ(r.data_hex(),
              "00 14 00 02 00 02 01 20 00 00 01 03 00 00 01 00 70 01 "
              "01 21 00 00 01 02 00 00 01 00 70 01");
}

TEST(WriteAccessLogRead, W342_5_3_30_BeginningBeyondTheStoredRecordsIs1103) {
    Harness h;
    h.send("0102 82000000 0001 0001");
    auto r = h.send("2140 0002 0001");
    EXPECT_EQ(r.end_code(), 0x1103);
    EXPECT_TRUE(r.data().empty());
    r = h.send("2140 0001 0005");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 14 00 01 00 00");
    EXPECT_EQ(h.send("2140 0000").end_code(), 0x1002);
    EXPECT_EQ(h.send("2140 0000 0001 00").end_code(), 0x1001);
}

TEST(WriteAccessLogRead, W342_5_3_30_TwentyNodesAndThenSomeKeepTwentyRecords) {
    Harness h;
    for (std::uint8_t node = 1; node <= 25; ++node)
        h.send("0102 82000000 0001 0001", from(node));
    auto r = h.send("2140 0000 0014");
    const auto d = r.data();
    ASSERT_EQ(d.size(), 6u + 20u * 12u);
    EXPECT_EQ(d[3], 20);
    EXPECT_EQ(d[6 + 1], 6);  // nodes 1-5 discarded
    EXPECT_EQ(d[6 + 19 * 12 + 1], 25);
}

TEST(WriteAccessLogClear, W342_5_3_31_ClearThenOnlyTheClearItselfIsLogged) {
    Harness h;
    h.send("0102 82000000 0001 0001", from(0x30));
    EXPECT_EQ(h.send("2141").end_code(), 0x0000);
    // 21 41 is itself a FINS write command (5-1-2), so the log holds it afterwards.
    ASSERT_EQ(h.plc.write_access_log().size(), 1u);
    EXPECT_EQ(h.plc.write_access_log().at(0).command, (CommandCode{0x21, 0x41}));
    EXPECT_EQ(h.send("2141 00").end_code(), 0x1001);
}

TEST(EndCodeFlags, W342_5_1_3_BatteryErrorSetsBit6OnAnOrdinaryRead) {
    Harness h;
    EXPECT_EQ(h.send("0101 82000000 0001").end_code(), 0x0000);
    h.plc.errors().set_battery_low(true, t0);
    auto r = h.send("0101 82000000 0001");
    EXPECT_EQ(r.end_code(), 0x0040);
    EXPECT_EQ(r.data_hex(), "00 00");  // still a normal completion with its data
    EXPECT_EQ(h.send("0101 82800000 0001").end_code(), 0x1103 | 0x0040);
    h.plc.errors().raise_fals(1, "", t0);
    EXPECT_EQ(h.send("0101 82000000 0001").end_code(), 0x00C0);
    h.plc.errors().set_battery_low(false, t0);
    EXPECT_EQ(h.send("0101 82000000 0001").end_code(), 0x0080);
}

TEST(WriteAccessLog, RecordAndFlagsDoNotAllocate) {
    Harness h;
    auto& log = h.plc.write_access_log();
    auto& errors = h.plc.errors();
    errors.set_battery_low(true, t0);
    log.record(client_node, {0x01, 0x02}, EndCode::normal_completion, t0);  // warm up
    const auto before = ::mallinfo2();
    std::uint16_t flags = 0;
    for (std::uint8_t n = 0; n < 100; ++n) {
        log.record(NodeAddress{0, n, 0}, {0x01, 0x02}, EndCode::normal_completion, t0);
        flags = static_cast<std::uint16_t>(flags | errors.end_code_flags());
    }
    const auto after = ::mallinfo2();
    EXPECT_EQ(after.uordblks, before.uordblks);
    EXPECT_EQ(after.hblkhd, before.hblkhd);
    EXPECT_EQ(flags, 0x0040);
}

}  // namespace
}  // namespace fins::test
