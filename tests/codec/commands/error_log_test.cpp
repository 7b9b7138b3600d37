// 21 01 .. 21 41 (W342 5-3-27 .. 5-3-31): round trips, prefixes, record layouts, BCD
// time stamps and the 5-3-27 code table.
#include <gtest/gtest.h>

#include <chrono>

#include "codec/test_support.hpp"
#include "fins/commands/error_log.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

template <class C>
void expect_prefixes_and_longer_fail(const std::vector<std::uint8_t>& params) {
    for (std::size_t n = 0; n < params.size(); ++n)
        EXPECT_EQ(C::decode(prefix(params, n)).error(), EndCode::command_too_short) << n;
    auto longer = params;
    longer.push_back(0);
    EXPECT_EQ(C::decode(longer).error(), EndCode::command_too_long);
}

TEST(ErrorClear, W342_5_3_27_RoundTrip) {
    const ErrorClear c{0x00F7};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("00F7"));
    auto d = ErrorClear::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->error_code, 0x00F7);
    expect_prefixes_and_longer_fail<ErrorClear>(params);
    EXPECT_EQ(encode(ErrorClear{}), hex("FFFE"));  // default: the current error
}

TEST(ErrorLogRead, W342_5_3_28_RoundTrip) {
    const ErrorLogRead c{0x0002, 0x0003};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("0002 0003"));
    auto d = ErrorLogRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->first, 2);
    EXPECT_EQ(d->count, 3);
    expect_prefixes_and_longer_fail<ErrorLogRead>(params);
}

TEST(ErrorLogRead, SEED003_RecordIsCodesThenMinuteSecondDayHourYearMonth) {
    ErrorLogReadResponse r;
    r.stored = 2;
    r.records = {{0x00F7, 0x0000, LogTime{26, 11, 22, 1, 47, 58}},
                 {0x4105, 0x0001, LogTime{99, 12, 31, 23, 59, 9}}};
    const auto data = encode(r);
    EXPECT_EQ(data,
              hex("0014 0002 0002  00F7 0000 47 58 22 01 26 11  4105 0001 59 09 31 23 99 12"));
    const ErrorLogRead request{0, 20};
    auto d = request.decode_response(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, r);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(request.decode_response(prefix(data, n))) << n;
    // More records than asked for, or a nibble above 9, is malformed.
    EXPECT_FALSE((ErrorLogRead{0, 1}.decode_response(data)));
    auto bad = data;
    bad[10] = 0x5A;
    EXPECT_FALSE(request.decode_response(bad));
}

TEST(ErrorLogClear, W342_5_3_29_NoParameters) {
    EXPECT_TRUE(encode(ErrorLogClear{}).empty());
    EXPECT_TRUE(ErrorLogClear::decode({}));
    EXPECT_EQ(ErrorLogClear::decode(hex("00")).error(), EndCode::command_too_long);
    EXPECT_FALSE(ErrorLogClear{}.decode_response(hex("00")));
}

TEST(WriteAccessLogRead, W342_5_3_30_RoundTripAndTwelveByteRecords) {
    const WriteAccessLogRead c{0, 20};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("0000 0014"));
    expect_prefixes_and_longer_fail<WriteAccessLogRead>(params);

    WriteAccessLogReadResponse r;
    r.stored = 1;
    r.records = {{NodeAddress{0x01, 0x14, 0x00}, 0x00, CommandCode{0x01, 0x02},
                  LogTime{26, 11, 22, 1, 47, 58}}};
    const auto data = encode(r);
    // network node unit 00, MRC SRC, minute second day hour year month (frames 6/2140).
    EXPECT_EQ(data, hex("0014 0001 0001  01 14 00 00 01 02 47 58 22 01 26 11"));
    auto d = c.decode_response(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, r);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(c.decode_response(prefix(data, n))) << n;
}

TEST(WriteAccessLogClear, W342_5_3_31_NoParameters) {
    EXPECT_TRUE(WriteAccessLogClear::decode({}));
    EXPECT_EQ(WriteAccessLogClear::decode(hex("00")).error(), EndCode::command_too_long);
}

TEST(LogTime, W342_5_3_19_UtcCalendarOfATimePoint) {
    using namespace std::chrono;
    const sys_days day = year{2026} / November / 22;
    EXPECT_EQ(to_log_time(day + hours{1} + minutes{47} + seconds{58} + milliseconds{999}),
              (LogTime{26, 11, 22, 1, 47, 58}));
    EXPECT_EQ(to_log_time(sys_days{year{1999} / December / 31} + hours{23}),
              (LogTime{99, 12, 31, 23, 0, 0}));
    EXPECT_EQ(to_log_time(system_clock::time_point{}), (LogTime{70, 1, 1, 0, 0, 0}));
}

TEST(ErrorCodeTable, W342_5_3_27_EveryListedCodeIsKnown) {
    // Both lists of 5-3-27 (FFFF and FFFE are requests, not errors).
    const std::uint16_t listed[] = {0x0003, 0x0010, 0x0011, 0x008A, 0x008B, 0x009A, 0x009B, 0x00A0,
                                    0x00A1, 0x00D1, 0x00D2, 0x00E7, 0x00F1, 0x00F7, 0x0200, 0x020F,
                                    0x02F0, 0x0300, 0x035F, 0x0400, 0x040F, 0x0500, 0x055F, 0x0600,
                                    0x060F, 0x4101, 0x42FF, 0x809F, 0x80C0, 0x80C7, 0x80E0, 0x80E1,
                                    0x80E9, 0x80EA, 0x80F0, 0x80F1, 0x82F0, 0xC101, 0xC2FF};
    for (auto code : listed)
        EXPECT_NE(find_error_code(code), nullptr) << std::hex << code;
    const std::uint16_t unlisted[] = {0x0000, 0x0001, 0x0210, 0x0360, 0x4100, 0x4300,
                                      0x80C8, 0xC100, 0xC300, 0xFFFF, 0xFFFE};
    for (auto code : unlisted)
        EXPECT_EQ(find_error_code(code), nullptr) << std::hex << code;
    // Fatal codes are the PROGRAM-mode-only list.
    for (const auto& e : error_code_table())
        EXPECT_EQ(e.fatal, e.program_mode_only) << e.name;
    EXPECT_EQ(find_error_code(0x00F7)->bit, 4);
    EXPECT_EQ(find_error_code(0x4105)->bit, 15);
    EXPECT_EQ(find_error_code(0xC105)->bit, 6);
    EXPECT_TRUE(find_error_code(0xC105)->fatal);
}

}  // namespace
}  // namespace fins
