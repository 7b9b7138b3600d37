// plc::WriteAccessLog: the record rules of W342 5-3-30.
#include <gtest/gtest.h>

#include <chrono>

#include "plc/plc.hpp"

namespace fins::plc {
namespace {

using namespace std::chrono;

const system_clock::time_point t0 = sys_days{year{2026} / November / 22} + hours{1};
constexpr CommandCode write_cmd{0x01, 0x02};

void write_from(WriteAccessLog& log, std::uint8_t node, system_clock::time_point t,
                CommandCode c = write_cmd) {
    log.record(NodeAddress{0x00, node, 0x00}, c, EndCode::normal_completion, t);
}

TEST(WriteAccessLog, W342_5_3_30_NewNodesAppendInOrder) {
    Plc plc;
    auto& log = plc.write_access_log();
    EXPECT_EQ(log.size(), 0u);
    write_from(log, 10, t0);
    write_from(log, 11, t0 + seconds{1}, CommandCode{0x07, 0x02});
    ASSERT_EQ(log.size(), 2u);
    EXPECT_EQ(log.at(0).source.node, 10);
    EXPECT_EQ(log.at(1).source.node, 11);
    EXPECT_EQ(log.at(1).command, (CommandCode{0x07, 0x02}));
    EXPECT_EQ(log.at(1).time, (LogTime{26, 11, 22, 1, 0, 1}));
    EXPECT_EQ(log.at(1).reserved, 0x00);
}

TEST(WriteAccessLog, W342_5_3_30_SameNodeOverwritesItsRecordInPlace) {
    Plc plc;
    auto& log = plc.write_access_log();
    write_from(log, 10, t0);
    write_from(log, 11, t0);
    log.record(NodeAddress{0x00, 10, 0x05}, CommandCode{0x01, 0x03}, EndCode::write_protected,
               t0 + minutes{5});
    ASSERT_EQ(log.size(), 2u);
    EXPECT_EQ(log.at(0).source, (NodeAddress{0x00, 10, 0x05}));  // unit updated with it
    EXPECT_EQ(log.at(0).command, (CommandCode{0x01, 0x03}));
    EXPECT_EQ(log.at(0).time.minute, 5);
    // Same node number on another network is another node.
    log.record(NodeAddress{0x02, 10, 0x00}, write_cmd, EndCode::normal_completion, t0);
    EXPECT_EQ(log.size(), 3u);
}

TEST(WriteAccessLog, W342_5_3_30_FullLogDiscardsTheLeastRecentlyWritten) {
    Plc plc;
    auto& log = plc.write_access_log();
    for (std::uint8_t n = 1; n <= 20; ++n)
        write_from(log, n, t0);
    write_from(log, 1, t0);  // node 1 writes again: its record is new now
    write_from(log, 21, t0);
    ASSERT_EQ(log.size(), 20u);
    EXPECT_EQ(log.at(0).source.node, 1);  // kept, in place
    EXPECT_EQ(log.at(1).source.node, 3);  // node 2 was the oldest
    EXPECT_EQ(log.at(19).source.node, 21);
    for (std::uint8_t n = 22; n < 80; ++n)
        write_from(log, n, t0);
    EXPECT_EQ(log.size(), 20u);
    EXPECT_EQ(log.at(0).source.node, 60);
    EXPECT_EQ(log.at(19).source.node, 79);
}

// The newest record written again (same node, command and second, as a scenario writes
// every tick) is kept as it is, and it still counts as the newest when the log is full.
TEST(WriteAccessLog, W342_5_3_30_TheNewestWrittenAgainStaysTheNewest) {
    Plc plc;
    auto& log = plc.write_access_log();
    write_from(log, 1, t0);
    write_from(log, 2, t0);
    write_from(log, 1, t0);  // not the newest: its record is new now
    write_from(log, 1, t0);  // the newest again, nothing changes
    write_from(log, 1, t0 + milliseconds{300});
    ASSERT_EQ(log.size(), 2u);
    for (std::uint8_t n = 3; n <= 20; ++n)
        write_from(log, n, t0);
    write_from(log, 20, t0);  // the newest, again
    write_from(log, 21, t0);  // discards node 2, the least recently written
    EXPECT_EQ(log.at(0).source.node, 1);
    EXPECT_EQ(log.at(1).source.node, 3);
    EXPECT_EQ(log.at(18).source.node, 20);
    EXPECT_EQ(log.at(19).source.node, 21);
    // The same node at another second or with another command is recorded.
    write_from(log, 21, t0 + seconds{2});
    EXPECT_EQ(log.at(19).time.second, 2);
    write_from(log, 21, t0 + seconds{2}, CommandCode{0x01, 0x03});
    EXPECT_EQ(log.at(19).command, (CommandCode{0x01, 0x03}));
    write_from(log, 22, t0);  // node 1 is the oldest now
    EXPECT_EQ(log.at(0).source.node, 3);
    EXPECT_EQ(log.at(19).source.node, 22);
}

// Setting the clock (W342 5-3-21) within the second of the newest record: the same
// writer's next write carries the new time.
TEST(WriteAccessLog, W342_5_3_30_AWriteAfterTheClockIsSetCarriesTheNewTime) {
    Plc plc;
    auto& log = plc.write_access_log();
    write_from(log, 1, t0);
    const auto before = log.at(0).time;
    ClockWrite set;
    set.year = 30;
    set.month = 1;
    set.day = 2;
    set.hour = 3;
    set.minute = 4;
    set.second = 5;
    ASSERT_EQ(plc.clock().write(set, t0), EndCode::normal_completion);
    write_from(log, 1, t0 + milliseconds{10});
    EXPECT_NE(log.at(0).time, before);
    EXPECT_EQ(log.at(0).time, (LogTime{30, 1, 2, 3, 4, 5}));
}

TEST(WriteAccessLog, W342_5_3_31_ClearEmptiesTheLog) {
    Plc plc;
    auto& log = plc.write_access_log();
    write_from(log, 1, t0);
    log.clear();
    EXPECT_EQ(log.size(), 0u);
    write_from(log, 2, t0);
    EXPECT_EQ(log.size(), 1u);
    EXPECT_EQ(log.at(0).source.node, 2);
}

}  // namespace
}  // namespace fins::plc
