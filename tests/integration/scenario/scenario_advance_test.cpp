// A long `finsd ctl scenario advance` in a finsd process (issue 26 point 4): it runs in
// slices, so FINS requests are answered while it runs; `finsd ctl` waits for its answer
// past its usual 5 s; the other verbs are refused meanwhile with a clear error; status
// answers with the progress.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

std::vector<std::string> ctl_argv(const std::string& socket, std::vector<std::string> args) {
    std::vector<std::string> argv{finsd_path, "ctl", "--socket", socket};
    argv.insert(argv.end(), args.begin(), args.end());
    return argv;
}

TEST(ScenarioAdvance, FinsRequestsAreAnsweredWhileALongAdvanceRuns) {
    ScratchDir dir("scenario-advance");
    const std::string socket = (dir.path() / "ctl.sock").string();
    // A 1 ms tick: an hour is 3.6 million ticks, seconds of work for finsd.
    const auto file = dir.write("long.toml", R"([scenario]
tick_ms = 1
time = "virtual"

[[scenario.signal]]
address = "D0"
kind = "ramp"
min = 0
max = 3600
period_s = 3600

[[scenario.signal]]
address = "D1"
kind = "sine"
min = 0
max = 1000
period_s = 7
)");
    Finsd d({"--scenario", file, "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    Child advance(ctl_argv(socket, {"advance", "3600"}));

    // Status answers while the advance runs, and says how far it is.
    bool advancing = false;
    for (int i = 0; i < 200 && !advancing && advance.running(); ++i) {
        const auto r = run(ctl_argv(socket, {"scenario", "status"}));
        ASSERT_EQ(r.exit_code, 0) << r.err;
        advancing = Json::parse(r.out, nullptr, false)["scenario"].contains("advancing");
    }
    ASSERT_TRUE(advancing) << "the advance ended before a status saw it running";

    // A FINS request is answered within 1 s (the client's timeout) meanwhile.
    ClientOptions o;
    o.port = d.port();
    o.timeout = std::chrono::milliseconds(1000);
    auto c = Client::connect(o);
    ASSERT_TRUE(c.has_value());
    auto read = (*c)->read_words(addr("D0"), 1);
    ASSERT_TRUE(read.has_value()) << read.error().message();

    // A second advance, a pause: refused, with the reason.
    const auto second = run(ctl_argv(socket, {"advance", "1"}));
    EXPECT_EQ(second.exit_code, 2);
    EXPECT_NE(second.err.find("an advance is running"), std::string::npos) << second.err;
    const auto pause = run(ctl_argv(socket, {"scenario", "pause"}));
    EXPECT_EQ(pause.exit_code, 2);
    EXPECT_NE(pause.err.find("an advance is running"), std::string::npos) << pause.err;

    // The advance answers when done, however long it took.
    const auto done = advance.wait(std::chrono::seconds(240));
    ASSERT_EQ(done.exit_code, 0) << done.err << done.out;
    const Json answer = Json::parse(done.out, nullptr, false);
    EXPECT_EQ(answer["ticks"], 3'600'000) << done.out;
    EXPECT_DOUBLE_EQ(answer["time_s"].get<double>(), 3600.0) << done.out;
    EXPECT_EQ(words_of(**c, "D0", 1), std::vector<std::uint16_t>{3600});
}

}  // namespace
}  // namespace fins::test
