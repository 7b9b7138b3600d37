// config::read_text_file: a configuration file read whole, up to a bound.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "config/text_file.hpp"

namespace fins::config {
namespace {

std::filesystem::path scratch(const std::string& name, const std::string& content) {
    const auto dir =
        std::filesystem::temp_directory_path() /
        ("fins-text-file-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    std::filesystem::create_directories(dir);
    const auto path = dir / name;
    std::ofstream(path, std::ios::binary) << content;
    return path;
}

TEST(TextFile, ReadsTheWholeFileUpToAndAtItsBound) {
    const auto path = scratch("ten.toml", "0123456789");
    EXPECT_EQ(read_text_file(path).value(), "0123456789");
    EXPECT_EQ(read_text_file(path, 10).value(), "0123456789");
    const auto empty = scratch("empty.toml", "");
    EXPECT_EQ(read_text_file(empty).value(), "");
    std::filesystem::remove_all(path.parent_path());
}

TEST(TextFile, OneByteOverTheBoundIsRefusedNamingTheFile) {
    const auto path = scratch("eleven.toml", "0123456789A");
    const auto r = read_text_file(path, 10);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), path.string() + ": larger than 10 bytes: not a configuration file");
    std::filesystem::remove_all(path.parent_path());
}

TEST(TextFile, AMissingFileCannotBeRead) {
    const auto r = read_text_file("/nonexistent/finsd.toml");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "/nonexistent/finsd.toml: cannot read the file");
}

// /dev/zero never ends: the bound is what ends the read.
TEST(TextFile, AFileThatNeverEndsStopsAtTheBound) {
    const auto r = read_text_file("/dev/zero");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "/dev/zero: larger than 16 MiB: not a configuration file");
}

}  // namespace
}  // namespace fins::config
