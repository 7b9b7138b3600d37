// docs/bridge.md's quick start runs as written: its shell block is run by bash in a
// scratch directory whose build/bin and packaging/ are this tree's, and every line of the
// output the page shows (with "ts" values as any number) is printed.
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "bridge_fixture.hpp"

namespace fins::bridge::test {
namespace {

// The fenced block that follows the first line starting with `after` (and the fence).
std::string block_after(const std::string& text, const std::string& after) {
    auto at = text.find(after);
    if (at == std::string::npos) return {};
    at = text.find("```", at);
    if (at == std::string::npos) return {};
    at = text.find('\n', at) + 1;
    const auto end = text.find("\n```", at);
    return text.substr(at, end - at + 1);
}

std::string without_ts(const std::string& line) {
    return std::regex_replace(line, std::regex("\"ts\":[0-9]+"), "\"ts\":N");
}

TEST(BridgeDocs, QuickStartRunsAsWritten) {
    fins::test::FixedPorts lock;  // 9600 and 1883, as the page says
    std::ifstream in(std::string(FINS_SOURCE_DIR) + "/docs/bridge.md");
    std::stringstream page;
    page << in.rdbuf();
    const std::string script = block_after(page.str(), "## Quick start");
    const std::string shown = block_after(page.str(), "prints, in some order");
    ASSERT_FALSE(script.empty());
    ASSERT_FALSE(shown.empty());
    ScratchDir dir("bridge-docs");
    std::filesystem::create_directories(dir.path() / "build");
    std::filesystem::create_directory_symlink(FINS_BIN_DIR, dir.path() / "build" / "bin");
    std::filesystem::create_directory_symlink(std::string(FINS_SOURCE_DIR) + "/packaging",
                                              dir.path() / "packaging");
    const auto file = dir.write("quick-start.sh", "cd " + dir.path().string() + "\n" + script);
    auto r = fins::test::Child({"/bin/bash", file}).wait(std::chrono::seconds(40));
    std::istringstream expected(shown);
    const std::string out = without_ts(r.out);
    for (std::string line; std::getline(expected, line);)
        EXPECT_NE(out.find(without_ts(line)), std::string::npos)
            << "docs/bridge.md shows: " << line << "\nthe quick start printed:\n"
            << r.out << r.err;
}

}  // namespace
}  // namespace fins::bridge::test
