// The `fins` verbs of 02 xx / 03 xx / 02 40 against a real finsd: output, JSON and exit
// codes (0 ok, 2 usage, 3 transport, 4 end code).
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fins/command_table.hpp"
#include "fins/commands/loop_control.hpp"
#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

std::filesystem::path temp_file(const std::string& name) {
    return std::filesystem::temp_directory_path() /
           ("fins-cli-plc-data-" + std::to_string(::getpid()) + "-" + name);
}

TEST(CliParameterArea, ReadWriteAndClearRoutingTables) {
    Finsd d({});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto w = d.fins({"param-write", "routing", "510", "0x0A0B", "12"});
    EXPECT_EQ(w.exit_code, 0) << w.err;
    EXPECT_EQ(w.out, "wrote 2 words at routing 01FE (2 words sent in 1 block)\n");
    auto r = d.fins({"param-read", "routing", "508"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "routing tables (8013) words 01FC-01FF\n01FC  0000 0000 0A0B 000C\n");
    auto j = d.fins({"param-read", "8013", "0x1FE", "--json"});
    ASSERT_EQ(j.exit_code, 0) << j.err;
    auto doc = nlohmann::json::parse(j.out);
    EXPECT_EQ(doc["area"], "8013");
    EXPECT_EQ(doc["start"], 510);
    EXPECT_EQ(doc["last_word"], true);
    EXPECT_EQ(doc["words"], nlohmann::json::parse("[2571, 12]"));
    auto c = d.fins({"param-clear", "routing"});
    EXPECT_EQ(c.exit_code, 0) << c.err;
    EXPECT_EQ(c.out, "cleared routing tables (8013), 512 words\n");
    EXPECT_EQ(
        nlohmann::json::parse(d.fins({"param-read", "routing", "510", "--json"}).out)["words"],
        nlohmann::json::parse("[0, 0]"));
}

TEST(CliParameterArea, W342_5_3_7_WriteToAWholeAreaRewritesItWhole) {
    Finsd d({});
    auto w = d.fins({"param-write", "plc-setup", "100", "1", "2", "3", "--json"});
    ASSERT_EQ(w.exit_code, 0) << w.err;
    auto doc = nlohmann::json::parse(w.out);
    EXPECT_EQ(doc["written"], 3);
    EXPECT_EQ(doc["transferred"], 512);
    EXPECT_EQ(doc["blocks"], 2);
    auto r = d.fins({"param-read", "plc-setup", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    doc = nlohmann::json::parse(r.out);
    EXPECT_EQ(doc["count"], 512);
    EXPECT_EQ(doc["words"][99], 0);
    EXPECT_EQ(doc["words"][100], 1);
    EXPECT_EQ(doc["words"][102], 3);
    // The whole CPU Bus Unit setup (5184 words) reads in 498-word blocks.
    auto all = d.fins({"param-read", "cpu-bus", "--json"});
    ASSERT_EQ(all.exit_code, 0) << all.err;
    EXPECT_EQ(nlohmann::json::parse(all.out)["words"].size(), 5184u);
}

TEST(CliParameterArea, W342_5_3_8_IoTableInRunModeExits4With2206) {
    Finsd d({"--mode", "run"});
    auto w = d.fins({"param-clear", "io-table", "--json"});
    EXPECT_EQ(w.exit_code, 4);
    EXPECT_EQ(nlohmann::json::parse(w.out)["error"]["end_code"], "2206");
    auto text = d.fins({"param-write", "io-table", "0", "1"});
    EXPECT_EQ(text.exit_code, 4);
    EXPECT_NE(text.err.find("2206"), std::string::npos) << text.err;
}

TEST(CliParameterArea, UsageErrorsExit2) {
    Finsd d({});
    auto area = d.fins({"param-read", "nowhere"});
    EXPECT_EQ(area.exit_code, 2);
    EXPECT_NE(area.err.find("plc-setup (8010)"), std::string::npos) << area.err;
    EXPECT_EQ(d.fins({"param-read", "plc-setup", "512"}).exit_code, 2);
    EXPECT_EQ(d.fins({"param-read", "plc-setup", "500", "13"}).exit_code, 2);
    EXPECT_EQ(d.fins({"param-write", "routing", "511", "1", "2"}).exit_code, 2);
    EXPECT_EQ(d.fins({"param-write", "routing", "0", "70000"}).exit_code, 2);
    EXPECT_EQ(d.fins({"param-clear", "8011"}).exit_code, 2);
}

TEST(CliProgramArea, W342_5_3_11_WriteReadBackAndClear) {
    Finsd d({"--profile", "cj1m", "--mode", "program"});
    ASSERT_TRUE(d.started()) << d.result().err;
    const auto image = temp_file("image.bin");
    const auto back = temp_file("back.bin");
    std::vector<char> bytes(2000);
    for (std::size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = static_cast<char>(i * 7 + 3);
    std::ofstream(image, std::ios::binary).write(bytes.data(), 2000);

    auto w = d.fins({"program-write", image.string()});
    EXPECT_EQ(w.exit_code, 0) << w.err;
    EXPECT_EQ(w.out, "wrote 2000 bytes at 00000000 in 3 blocks\n");
    auto r = d.fins({"program-read", "0", "2000", "--out", back.string()});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(back, std::ios::binary);
    std::vector<char> got((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(got, bytes);

    auto dump = d.fins({"program-read", "16", "16"});
    EXPECT_EQ(dump.exit_code, 0) << dump.err;
    EXPECT_EQ(dump.out.substr(0, 13), "00000010  73 ");  // 16 x 7 + 3

    // Without BYTES the read runs to the last address (bit 15): the CJ1M-CPU13's program
    // area of 40 K words (20K steps, as 05 01 reports it) = 81,920 bytes.
    auto whole = d.fins({"program-read", "--out", back.string(), "--json"});
    ASSERT_EQ(whole.exit_code, 0) << whole.err;
    auto doc = nlohmann::json::parse(whole.out);
    EXPECT_EQ(doc["bytes"], 81920);
    EXPECT_EQ(doc["last"], true);
    EXPECT_EQ(std::filesystem::file_size(back), 81920u);

    auto c = d.fins({"program-clear", "--with-interrupt-tasks"});
    EXPECT_EQ(c.exit_code, 0) << c.err;
    EXPECT_EQ(c.out, "program area cleared (with interrupt tasks)\n");
    auto zero = d.fins({"program-read", "0", "8", "--json"});
    EXPECT_EQ(nlohmann::json::parse(zero.out)["data"], "0000000000000000");
    std::filesystem::remove(image);
    std::filesystem::remove(back);
}

TEST(CliProgramArea, HexFilesBothWays) {
    Finsd d({"--profile", "cj1m", "--mode", "program"});
    const auto image = temp_file("image.hex");
    const auto back = temp_file("back.hex");
    std::ofstream(image) << "DEADBEEF 01020304\n0A0B0C0D\n";
    auto w = d.fins({"program-write", image.string(), "--hex", "--start", "0x40"});
    EXPECT_EQ(w.exit_code, 0) << w.err;
    auto r = d.fins({"program-read", "0x40", "12", "--out", back.string(), "--hex"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(back);
    std::string text;
    std::getline(in, text);
    EXPECT_EQ(text, "DEADBEEF010203040A0B0C0D");
    std::filesystem::remove(image);
    std::filesystem::remove(back);
}

TEST(CliProgramArea, W342_5_3_11_RunModeAndUsageErrors) {
    Finsd d({"--profile", "cj1m", "--mode", "run"});
    const auto image = temp_file("odd.bin");
    std::ofstream(image, std::ios::binary).write("abcdefgh", 8);
    auto w = d.fins({"program-write", image.string(), "--json"});
    EXPECT_EQ(w.exit_code, 4);
    EXPECT_EQ(nlohmann::json::parse(w.out)["error"]["end_code"], "2206");
    EXPECT_EQ(d.fins({"program-clear"}).exit_code, 4);
    // Reading works in RUN mode.
    EXPECT_EQ(d.fins({"program-read", "0", "4"}).exit_code, 0);
    std::ofstream(image, std::ios::binary).write("abcdef", 6);
    EXPECT_EQ(d.fins({"program-write", image.string()}).exit_code, 2);
    EXPECT_EQ(d.fins({"program-write", temp_file("missing").string()}).exit_code, 2);
    EXPECT_EQ(d.fins({"program-read", "2", "4"}).exit_code, 2);
    EXPECT_EQ(d.fins({"program-read", "0", "6"}).exit_code, 2);
    std::filesystem::remove(image);
}

// loop-read addresses the Inner Board (unit E1): a CPU without one has no such unit
// (0202), and 02 40 sent to the CPU Unit itself is undefined there (0401).
TEST(CliLoopControl, Seed001_LoopReadAnswersFromTheInnerBoard) {
    Finsd plain({});
    auto none = plain.fins({"loop-read", "1", "6", "--json"});
    EXPECT_EQ(none.exit_code, 4);
    EXPECT_EQ(nlohmann::json::parse(none.out)["error"]["end_code"], "0202");
    auto cpu = plain.fins({"--dest", "0.0.0", "loop-read", "1", "6", "--json"});
    EXPECT_EQ(nlohmann::json::parse(cpu.out)["error"]["end_code"], "0401");
    EXPECT_EQ(plain.fins({"loop-read", "1000", "6"}).exit_code, 2);
    EXPECT_EQ(plain.fins({"loop-read", "1", "x"}).exit_code, 2);

    Finsd board({"--profile", "cs1h-lcb"});
    auto r = board.fins({"loop-read", "1", "6", "99", "30", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto doc = nlohmann::json::parse(r.out);
    EXPECT_EQ(doc["read"], 2);
    EXPECT_EQ(doc["items"][0]["value"], 4500);
    EXPECT_EQ(doc["items"][1]["item"], 30);
    EXPECT_EQ(doc["items"][1]["value"], 3600);
}

}  // namespace
}  // namespace fins::test
