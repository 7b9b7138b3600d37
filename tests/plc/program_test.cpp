// plc::UserProgram (W342 5-3-10 .. 5-3-12): UM size from the profile, the rules of
// program.hpp on the model alone, and retention across a restart.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <string>
#include <vector>

#include "plc/program.hpp"

namespace fins::plc {
namespace {

Profile small_um() {
    Profile p = cj2h();
    p.program_kwords = 1;  // 2,048 bytes
    return p;
}

std::vector<std::uint8_t> pattern(std::size_t n, std::uint8_t first) {
    std::vector<std::uint8_t> v(n);
    for (std::size_t i = 0; i < n; ++i)
        v[i] = static_cast<std::uint8_t>(first + i);
    return v;
}

TEST(UserProgramModel, W342_5_3_15_UmSizeIsKWordsOfTwoBytes) {
    Storage storage;
    Profile p = cj2h();
    UserProgram program(p, storage);
    EXPECT_EQ(program.size(), std::uint32_t{p.program_kwords} * 1024u * 2u);
    Storage other;
    EXPECT_EQ(UserProgram(small_um(), other).size(), 2048u);
    for (auto b : program.bytes())
        ASSERT_EQ(b, 0);
}

TEST(UserProgramModel, W342_5_3_10_ReadPlanRules) {
    Storage storage;
    UserProgram program(small_um(), storage);
    auto code = [&](ProgramAreaRead c) {
        auto r = program.plan_read(c);
        return r ? r->code : static_cast<EndCode>(r.error().value());
    };
    EXPECT_EQ(code({0xFFFF, 0, 992, false}), EndCode::normal_completion);
    EXPECT_EQ(code({0x0000, 0, 4, false}), EndCode::program_missing);
    EXPECT_EQ(code({0xFFFF, 0, 4, true}), EndCode::parameter_error);
    EXPECT_EQ(code({0xFFFF, 2, 4, false}), EndCode::access_size_error);
    EXPECT_EQ(code({0xFFFF, 0, 6, false}), EndCode::access_size_error);
    EXPECT_EQ(code({0xFFFF, 0, 996, false}), EndCode::response_too_long);
    EXPECT_EQ(code({0xFFFF, 2048, 4, false}), EndCode::address_range_error);
    auto cut = program.plan_read({0xFFFF, 2040, 16, false});
    ASSERT_TRUE(cut);
    EXPECT_EQ(cut->code, EndCode::address_range_exceeded);
    EXPECT_EQ(cut->range.count, 8);
    EXPECT_TRUE(cut->range.includes_last);
    auto exact = program.plan_read({0xFFFF, 2044, 4, false});
    ASSERT_TRUE(exact);
    EXPECT_EQ(exact->code, EndCode::normal_completion);
    EXPECT_TRUE(exact->range.includes_last);
}

TEST(UserProgramModel, W342_5_3_11_WritePlanRules) {
    Storage storage;
    UserProgram program(small_um(), storage);
    const auto data = pattern(996, 0);
    auto code = [&](std::uint16_t number, std::uint32_t address, std::uint16_t count,
                    std::size_t data_size) {
        auto r = program.plan_write({number, address, count, false, Bytes(data.data(), data_size)});
        return r ? EndCode::normal_completion : static_cast<EndCode>(r.error().value());
    };
    EXPECT_EQ(code(0xFFFF, 0, 996, 996), EndCode::normal_completion);
    EXPECT_EQ(code(0x0001, 0, 4, 4), EndCode::program_missing);
    EXPECT_EQ(code(0xFFFF, 0, 1000, 996), EndCode::command_too_long);
    EXPECT_EQ(code(0xFFFF, 1, 4, 4), EndCode::access_size_error);
    EXPECT_EQ(code(0xFFFF, 0, 5, 5), EndCode::access_size_error);
    EXPECT_EQ(code(0xFFFF, 2048, 4, 4), EndCode::address_range_error);
    EXPECT_EQ(code(0xFFFF, 2044, 8, 8), EndCode::address_range_exceeded);
    EXPECT_EQ(code(0xFFFF, 0, 8, 4), EndCode::elements_data_mismatch);
    program.set_prohibit_overwrite(true);
    EXPECT_EQ(code(0xFFFF, 0, 4, 4), EndCode::write_protected);
}

TEST(UserProgramModel, W342_5_3_11_WriteThenReadAndTheDownloadFlag) {
    Storage storage;
    UserProgram program(small_um(), storage);
    const auto data = pattern(8, 0x10);
    auto range = program.plan_write({0xFFFF, 16, 8, false, data});
    ASSERT_TRUE(range);
    program.write(*range, data, false);
    EXPECT_TRUE(program.download_in_progress());
    range = program.plan_write({0xFFFF, 24, 8, true, data});
    ASSERT_TRUE(range);
    program.write(*range, data, true);
    EXPECT_FALSE(program.download_in_progress());
    auto plan = program.plan_read({0xFFFF, 16, 16, false});
    ASSERT_TRUE(plan);
    std::vector<std::uint8_t> out(16);
    ByteWriter w(out);
    program.read(plan->range, w);
    EXPECT_EQ(w.size(), 16u);
    EXPECT_EQ(out, (std::vector<std::uint8_t>{0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x10,
                                              0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17}));
}

TEST(UserProgramModel, W342_5_3_12_ClearCodesAndProtection) {
    Storage storage;
    UserProgram program(small_um(), storage);
    program.bytes()[100] = 0xAA;
    EXPECT_EQ(program.check_clear({0xFFFF, 0x00}), EndCode::normal_completion);
    EXPECT_EQ(program.check_clear({0xFFFF, 0x10}), EndCode::normal_completion);
    EXPECT_EQ(program.check_clear({0xFFFF, 0x01}), EndCode::parameter_error);
    EXPECT_EQ(program.check_clear({0xFFFF, 0xFF}), EndCode::parameter_error);
    EXPECT_EQ(program.check_clear({0x0000, 0x00}), EndCode::program_missing);
    program.set_prohibit_overwrite(true);
    EXPECT_EQ(program.check_clear({0xFFFF, 0x00}), EndCode::write_protected);
    program.set_prohibit_overwrite(false);
    program.set_prohibit_transfer(true);
    program.clear(clear_with_interrupt_tasks);
    EXPECT_EQ(program.bytes()[100], 0);
    EXPECT_TRUE(program.interrupt_tasks());
    EXPECT_FALSE(program.prohibit_transfer());
    program.clear(clear_without_interrupt_tasks);
    EXPECT_FALSE(program.interrupt_tasks());
}

TEST(UserProgramRetention, TheProgramSurvivesARestart) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("fins-program-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    const auto data = pattern(8, 0xC0);
    {
        auto storage = Storage::open(dir, "test-program");
        ASSERT_TRUE(storage) << storage.error().message();
        UserProgram program(small_um(), **storage);
        ASSERT_TRUE((*storage)->seal());
        auto range = program.plan_write({0xFFFF, 2040, 8, true, data});
        ASSERT_TRUE(range);
        program.write(*range, data, true);
        program.set_prohibit_transfer(true);
    }
    {
        auto storage = Storage::open(dir, "test-program");
        ASSERT_TRUE(storage) << storage.error().message();
        UserProgram program(small_um(), **storage);
        ASSERT_TRUE((*storage)->seal());
        EXPECT_EQ(program.bytes()[2040], 0xC0);
        EXPECT_EQ(program.bytes()[2047], 0xC7);
        EXPECT_TRUE(program.prohibit_transfer());
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace fins::plc
