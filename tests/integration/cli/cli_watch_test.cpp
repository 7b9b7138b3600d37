// `fins watch` against a real finsd: the first poll prints every value, later polls only
// changes; --json gives one object per line; --count and --duration end it with exit 0,
// and so does SIGINT (Ctrl-C) in the middle of a run. Nothing here asserts on timing:
// the changes are made between lines the test has already read.
#include <signal.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"
#include "integration/support/process.hpp"

namespace fins::test {
namespace {

const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";

class CliWatch : public ::testing::Test {
  protected:
    void SetUp() override { ASSERT_TRUE(finsd_.started()) << finsd_.result().err; }
    std::vector<std::string> argv(std::vector<std::string> args) const {
        std::vector<std::string> v{fins_bin, "--port", std::to_string(finsd_.port()), "watch"};
        v.insert(v.end(), args.begin(), args.end());
        return v;
    }
    static std::vector<std::string> lines(const std::string& out) {
        std::vector<std::string> v;
        std::istringstream in(out);
        for (std::string line; std::getline(in, line);)
            v.push_back(line);
        return v;
    }

    Finsd finsd_{{}};
};

TEST_F(CliWatch, W342_5_3_5_FirstPollPrintsEveryValueThenOnlyChanges) {
    ASSERT_TRUE(finsd_.client()->write_words(addr("D0"), std::vector<std::uint16_t>{5}));
    const auto r = run(argv({"D0", "D1.3", "--count", "3", "--interval", "0.01", "--json"}));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const auto got = lines(r.out);
    ASSERT_EQ(got.size(), 2u) << r.out;  // nothing changed after the first poll
    const auto d0 = nlohmann::json::parse(got[0], nullptr, false);
    EXPECT_EQ(d0["address"], "D0");
    EXPECT_EQ(d0["value"], 5);
    EXPECT_TRUE(d0["time"].is_string());
    EXPECT_EQ(nlohmann::json::parse(got[1], nullptr, false)["address"], "D1.03");
}

TEST_F(CliWatch, PrintsAChangeAndCtrlCExitsZero) {
    Child watch(argv({"D0", "--interval", "0.02", "--duration", "120"}));
    const auto first = watch.read_line();
    EXPECT_NE(first.find("  D0  0"), std::string::npos) << first;
    ASSERT_TRUE(finsd_.client()->write_words(addr("D0"), std::vector<std::uint16_t>{7}));
    const auto change = watch.read_line();
    EXPECT_NE(change.find("  D0  7"), std::string::npos) << change;
    watch.terminate(SIGINT);
    const auto r = watch.wait();
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
}

TEST_F(CliWatch, DurationEndsTheWatchWithExitZero) {
    const auto r = run(argv({"W0", "--interval", "0.05", "--duration", "0.2"}));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(lines(r.out).size(), 1u) << r.out;
    EXPECT_NE(r.out.find("  W0  0\n"), std::string::npos) << r.out;
}

TEST_F(CliWatch, BadArgumentsAreUsageErrors) {
    EXPECT_EQ(run(argv({"Q5", "--count", "1"})).exit_code, 2);
    EXPECT_EQ(run(argv({"D0", "--interval", "0"})).exit_code, 2);
    EXPECT_EQ(run(argv({"D0", "--count", "0"})).exit_code, 2);
    const auto r = run(argv({"--count", "1"}));
    EXPECT_EQ(r.exit_code, 2);
}

// --as shows each value in `fins read`'s formats; a multi-word type reads its words from
// the address on, and a change in any of them is a change of the value.
TEST_F(CliWatch, AsShowsValuesInTheirTypeReadingEveryWordOfIt) {
    const auto client = finsd_.client();
    auto& c = *client;
    ASSERT_TRUE(c.write_float(addr("D100"), 1.5F));
    ASSERT_TRUE(c.write_int32(addr("D110"), -70000));
    ASSERT_TRUE(c.write_words(addr("D120"), std::vector<std::uint16_t>{0x4142, 0x4300}));
    ASSERT_TRUE(c.write_words(addr("D130"), std::vector<std::uint16_t>{0x1234, 0x12AB}));
    const auto r = run(argv({"D100", "--as", "float", "--count", "1", "--json"}));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const auto doc = nlohmann::json::parse(r.out, nullptr, false);
    EXPECT_EQ(doc["address"], "D100");
    EXPECT_EQ(doc["value"], 1.5) << r.out;
    const auto i32 = run(argv({"D110", "--as", "int32", "--count", "1"}));
    EXPECT_EQ(i32.exit_code, 0) << i32.err;
    EXPECT_NE(i32.out.find("  D110  -70000\n"), std::string::npos) << i32.out;
    const auto text = run(argv({"D120", "--as", "string", "--words", "2", "--count", "1"}));
    EXPECT_EQ(text.exit_code, 0) << text.err;
    EXPECT_NE(text.out.find("  D120  \"ABC\"\n"), std::string::npos) << text.out;
    // A word that is not BCD is shown as such and the watch goes on (the next change may
    // be BCD again): null in JSON.
    const auto bcd = run(argv({"D130", "D131", "--as", "bcd", "--count", "1"}));
    EXPECT_EQ(bcd.exit_code, 0) << bcd.err;
    EXPECT_NE(bcd.out.find("  D130  1234\n"), std::string::npos) << bcd.out;
    EXPECT_NE(bcd.out.find("  D131  not bcd: 0x12AB\n"), std::string::npos) << bcd.out;
    const auto ir = run(argv({"IR0", "--as", "hex", "--count", "1"}));
    EXPECT_NE(ir.out.find("  IR0  0x00000000\n"), std::string::npos) << ir.out << ir.err;
    // T5 --as bits: the completion flag, as `fins read T5 --as bits`.
    const auto flag = run(argv({"T5", "CIO0.03", "--as", "bits", "--count", "1"}));
    EXPECT_EQ(flag.exit_code, 0) << flag.err;
    EXPECT_EQ(lines(flag.out).size(), 2u) << flag.out;

    // The high word of an int32 changing is a change of the value.
    Child watch(argv({"D110", "--as", "int32", "--interval", "0.02", "--duration", "120"}));
    EXPECT_NE(watch.read_line().find("  D110  -70000"), std::string::npos);
    ASSERT_TRUE(c.write_words(addr("D111"), std::vector<std::uint16_t>{0}));
    const auto change = watch.read_line();
    EXPECT_NE(change.find("  D110  61072"), std::string::npos) << change;  // 0x0000EE90
    watch.terminate(SIGINT);
    EXPECT_EQ(watch.wait().exit_code, 0);
}

TEST_F(CliWatch, AsMistakesAreUsageErrorsWithTheReason) {
    const auto expect_usage = [this](std::vector<std::string> args, const std::string& message) {
        args.insert(args.end(), {"--count", "1"});
        const auto r = run(argv(args));
        EXPECT_EQ(r.exit_code, 2) << r.out;
        EXPECT_EQ(r.out, "");
        EXPECT_EQ(r.err, "fins: " + message + "\n");
    };
    expect_usage({"D0", "--as", "int64"},
                 "unknown --as format 'int64' (int16 uint16 int32 uint32 float double bcd bcd32 "
                 "string bits hex)");
    expect_usage({"D0", "--as", "bits"}, "D0 is a word: name a bit (D0.00) to watch bits");
    expect_usage({"CIO0.01", "--as", "int32"}, "CIO0.01 names a bit: use --as bits");
    expect_usage({"D0", "--as", "string"},
                 "--as string needs --words N, the words of each value (2 characters a word)");
    expect_usage({"D0", "--words", "2"}, "--words is the length of an --as string value");
    expect_usage({"D32766", "--as", "double"},
                 "D32766: 4 words from D32766 run past D32767, the last word of the area");
    expect_usage({"IR0", "--as", "float"},
                 "IR0 is a 32-bit index register: use --as uint32, int32 or hex");
}

// A poll the PLC refuses ends the watch with the end code's exit status (4): a CJ1M has
// no EM (W342 5-2-2), so its answer to E0_0 is an end code, not a value.
TEST(CliWatchRefused, W342_5_3_5_RefusedPollEndsWithExit4) {
    Finsd cj1m({"--profile", "cj1m"});
    ASSERT_TRUE(cj1m.started()) << cj1m.result().err;
    const auto r = run({fins_bin, "--port", std::to_string(cj1m.port()), "watch", "D0", "E0_0",
                        "--count", "2", "--interval", "0.01"});
    EXPECT_EQ(r.exit_code, 4) << r.out << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("fins: watch: the PLC answered"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace fins::test
