// plc::ParameterAreas (W342 5-3-7 .. 5-3-9): the rules of parameter_areas.hpp on the
// model alone, the 8000 layout and retention across a restart.
#include <gtest/gtest.h>

#include <unistd.h>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "plc/parameter_areas.hpp"

namespace fins::plc {
namespace {

std::vector<std::uint8_t> word_bytes(std::size_t count, std::uint16_t first) {
    std::vector<std::uint8_t> out;
    for (std::size_t i = 0; i < count; ++i) {
        const auto w = static_cast<std::uint16_t>(first + i);
        out.push_back(static_cast<std::uint8_t>(w >> 8));
        out.push_back(static_cast<std::uint8_t>(w));
    }
    return out;
}

struct Fixture : ::testing::Test {
    Storage storage;
    ParameterAreas params{cj2h(), storage};

    EndCode write(std::uint16_t area, std::uint16_t start, const std::vector<std::uint8_t>& data,
                  bool last) {
        const ParameterAreaWrite c{area, start, static_cast<std::uint16_t>(data.size() / 2), last,
                                   data};
        const auto range = params.plan_write(c);
        if (!range) return static_cast<EndCode>(range.error().value());
        return params.write(*range, data);
    }
    // Writes a whole area in 498-word blocks, bit 15 on the last.
    EndCode write_all(std::uint16_t area, std::uint16_t first_value) {
        const auto words = params.words(area).size();
        for (std::size_t at = 0; at < words; at += max_parameter_words) {
            const auto n = std::min<std::size_t>(max_parameter_words, words - at);
            const auto code =
                write(area, static_cast<std::uint16_t>(at),
                      word_bytes(n, static_cast<std::uint16_t>(first_value + at)), at + n == words);
            if (code != EndCode::normal_completion) return code;
        }
        return EndCode::normal_completion;
    }
};

using ParameterAreasModel = Fixture;

TEST_F(ParameterAreasModel, NewCpuUnitHasZeroedAreas) {
    for (const auto& area : parameter_area_table()) {
        const auto words = params.words(area.code);
        ASSERT_EQ(words.size(), area.words);
        for (auto w : words)
            ASSERT_EQ(w, 0);
    }
    EXPECT_TRUE(params.words(0x8011).empty());
}

TEST_F(ParameterAreasModel, W342_5_3_7_AreasAreViewsOfThe8000Range) {
    params.words(parameter_area_io_table)[0] = 0x1111;
    params.words(parameter_area_routing_tables)[0x1FF] = 0x2222;
    params.words(parameter_area_cpu_bus_unit_setup)[0x143F] = 0x3333;
    const auto all = params.words(parameter_area_all);
    EXPECT_EQ(all[0x0400], 0x1111);
    EXPECT_EQ(all[0x0AFF], 0x2222);
    EXPECT_EQ(all[0x1F3F], 0x3333);
}

TEST_F(ParameterAreasModel, W342_5_3_8_WholeAreaBecomesLiveOnlyWithTheLastWord) {
    // Block 1 of the PLC Setup: staged, not live ("or no data will be written").
    EXPECT_EQ(write(parameter_area_plc_setup, 0, word_bytes(498, 1), false),
              EndCode::normal_completion);
    EXPECT_TRUE(params.staging());
    EXPECT_EQ(params.words(parameter_area_plc_setup)[0], 0);
    EXPECT_EQ(write(parameter_area_plc_setup, 498, word_bytes(14, 499), true),
              EndCode::normal_completion);
    EXPECT_FALSE(params.staging());
    const auto live = params.words(parameter_area_plc_setup);
    EXPECT_EQ(live[0], 1);
    EXPECT_EQ(live[511], 512);
}

TEST_F(ParameterAreasModel, W342_5_3_7_WholeAreaBlocksMustFollowEachOtherFromWordZero) {
    // Starting anywhere but 0000 with nothing staged: 110C.
    EXPECT_EQ(write(parameter_area_io_table, 498, word_bytes(2, 0), false),
              EndCode::parameter_error);
    EXPECT_EQ(write(parameter_area_io_table, 0, word_bytes(498, 0), false),
              EndCode::normal_completion);
    // A gap: 110C, and the staged data is dropped (the next block must restart at 0).
    EXPECT_EQ(write(parameter_area_io_table, 500, word_bytes(498, 0), false),
              EndCode::parameter_error);
    EXPECT_FALSE(params.staging());
    EXPECT_EQ(write(parameter_area_io_table, 498, word_bytes(498, 0), false),
              EndCode::parameter_error);
    EXPECT_EQ(write_all(parameter_area_io_table, 7), EndCode::normal_completion);
    EXPECT_EQ(params.words(parameter_area_io_table)[1279], 7 + 1279);
}

TEST_F(ParameterAreasModel, W342_5_3_7_RoutingTablesAreWrittenInPlace) {
    EXPECT_EQ(write(parameter_area_routing_tables, 0x10, word_bytes(2, 0xAB00), false),
              EndCode::normal_completion);
    EXPECT_EQ(params.words(parameter_area_routing_tables)[0x10], 0xAB00);
    EXPECT_EQ(params.words(parameter_area_routing_tables)[0x11], 0xAB01);
    EXPECT_FALSE(params.staging());
}

TEST_F(ParameterAreasModel, W342_5_3_7_All8000RoundTripsThroughTheReservedBlock) {
    EXPECT_EQ(write_all(parameter_area_all, 0x100), EndCode::normal_completion);
    EXPECT_EQ(params.words(parameter_area_plc_setup)[0], 0x100);
    EXPECT_EQ(params.words(parameter_area_all)[0x0200], 0x300);  // reserved block
    EXPECT_EQ(params.words(parameter_area_io_table)[0], 0x100 + 0x400);
    EXPECT_EQ(params.words(parameter_area_routing_tables)[0], 0x100 + 0x900);
    EXPECT_EQ(params.words(parameter_area_cpu_bus_unit_setup)[0], 0x100 + 0xB00);
}

TEST_F(ParameterAreasModel, W342_5_3_8_IoTableFlagMarksRangesTouchingIt) {
    const auto data = word_bytes(2, 0);
    auto in_all = params.plan_write({parameter_area_all, 0x03FF, 2, false, data});
    ASSERT_TRUE(in_all);
    EXPECT_TRUE(in_all->io_table);
    auto before = params.plan_write({parameter_area_all, 0x03FD, 2, false, data});
    ASSERT_TRUE(before);
    EXPECT_FALSE(before->io_table);
    auto after = params.plan_write({parameter_area_all, 0x0900, 2, false, data});
    ASSERT_TRUE(after);
    EXPECT_FALSE(after->io_table);
    auto table = params.plan_write({parameter_area_io_table, 0x10, 2, false, data});
    ASSERT_TRUE(table);
    EXPECT_TRUE(table->io_table);
    auto clear = params.plan_clear({parameter_area_io_table, 0, 1280, false, 0});
    ASSERT_TRUE(clear);
    EXPECT_TRUE(clear->io_table);
}

TEST_F(ParameterAreasModel, W342_5_3_9_ClearZeroesTheWholeAreaAndDropsStagedData) {
    params.words(parameter_area_cpu_bus_unit_setup)[100] = 5;
    EXPECT_EQ(write(parameter_area_cpu_bus_unit_setup, 0, word_bytes(10, 1), false),
              EndCode::normal_completion);
    auto range = params.plan_clear({parameter_area_cpu_bus_unit_setup, 0, 5184, false, 0});
    ASSERT_TRUE(range);
    params.clear(*range);
    EXPECT_EQ(params.words(parameter_area_cpu_bus_unit_setup)[100], 0);
    EXPECT_FALSE(params.staging());
    // Bit 15 in the count is accepted either way.
    EXPECT_TRUE(params.plan_clear({parameter_area_cpu_bus_unit_setup, 0, 5184, true, 0}));
}

TEST_F(ParameterAreasModel, W342_5_3_7_ReadPlansCutAtTheEndAndAt498) {
    auto plan = params.plan_read({parameter_area_plc_setup, 500, 20, false});
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->range.count, 12);
    EXPECT_TRUE(plan->range.includes_last);
    EXPECT_EQ(plan->code, EndCode::address_range_exceeded);
    plan = params.plan_read({parameter_area_cpu_bus_unit_setup, 0, 600, false});
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->range.count, 498);
    EXPECT_FALSE(plan->range.includes_last);
    EXPECT_EQ(plan->code, EndCode::response_too_long);
    plan = params.plan_read({parameter_area_plc_setup, 14, 498, false});
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->code, EndCode::normal_completion);
    EXPECT_TRUE(plan->range.includes_last);
}

TEST(ParameterAreasRetention, AreasSurviveARestartStagedDataDoesNot) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("fins-param-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    {
        auto storage = Storage::open(dir, "test-params");
        ASSERT_TRUE(storage) << storage.error().message();
        ParameterAreas params(cj2h(), **storage);
        ASSERT_TRUE((*storage)->seal());
        const auto data = word_bytes(2, 0x4242);
        auto range = params.plan_write({parameter_area_routing_tables, 4, 2, false, data});
        ASSERT_TRUE(range);
        EXPECT_EQ(params.write(*range, data), EndCode::normal_completion);
        auto staged = params.plan_write({parameter_area_plc_setup, 0, 2, false, data});
        ASSERT_TRUE(staged);
        EXPECT_EQ(params.write(*staged, data), EndCode::normal_completion);
        EXPECT_TRUE(params.staging());
    }
    {
        auto storage = Storage::open(dir, "test-params");
        ASSERT_TRUE(storage) << storage.error().message();
        ParameterAreas params(cj2h(), **storage);
        ASSERT_TRUE((*storage)->seal());
        EXPECT_TRUE((*storage)->restored());
        EXPECT_EQ(params.words(parameter_area_routing_tables)[4], 0x4242);
        EXPECT_EQ(params.words(parameter_area_routing_tables)[5], 0x4243);
        EXPECT_FALSE(params.staging());
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace fins::plc
