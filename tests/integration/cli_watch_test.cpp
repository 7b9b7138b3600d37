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

#include "integration/finsd_run.hpp"
#include "integration/process.hpp"

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
