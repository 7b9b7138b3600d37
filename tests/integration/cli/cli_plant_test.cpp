// `fins --dest NET.NODE.UNIT` against a three-network plant (plant_fixture.hpp): relayed
// answers read as any other; a relay error names the router and carries the relay word
// in text and --json (README "Seeing relay errors in the CLI").
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration/support/plant_fixture.hpp"
#include "integration/support/process.hpp"

namespace fins::test {
namespace {

const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";

RunResult fins_cli(PlantThread& plant, std::vector<std::string> args) {
    std::vector<std::string> argv{
        fins_bin, "--host", "127.0.1.1", "--port", std::to_string(plant.port(0)), "--timeout", "2"};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

TEST(CliPlant, RelayedReadAndWriteThroughTwoRouters) {
    PlantThread plant;
    auto w = fins_cli(plant, {"--dest", "3.5.0", "write", "D10", "7", "8"});
    EXPECT_EQ(w.exit_code, 0) << w.err;
    auto r = fins_cli(plant, {"--dest", "3.5.0", "read", "D10", "2"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "D10  7\nD11  8\n");
}

// Issue 18 item 12: probe asks the --dest it is given (through the routers, like any
// request), not node 00 of the host it talks to.
TEST(CliPlant, ProbeAsksTheRoutedDest) {
    PlantThread plant;
    auto local = fins_cli(plant, {"--json", "probe"});
    auto far = fins_cli(plant, {"--json", "--dest", "3.5.0", "probe"});
    EXPECT_EQ(far.exit_code, 0) << far.err;
    EXPECT_NE(far.out.find(R"("node":"3.5.0")"), std::string::npos) << far.out;
    EXPECT_NE(far.out, local.out);
    auto nowhere = fins_cli(plant, {"--dest", "9.5.0", "probe"});
    EXPECT_EQ(nowhere.exit_code, 4) << nowhere.out;
    EXPECT_NE(nowhere.err.find("relay error: the router at network 1 node 1"), std::string::npos)
        << nowhere.err;
}

TEST(CliPlant, W342_5_1_3_RelayErrorNamesTheRouterInTextAndJson) {
    PlantThread plant;
    auto text = fins_cli(plant, {"--dest", "9.5.0", "read", "D10"});
    EXPECT_EQ(text.exit_code, 4);
    EXPECT_NE(text.err.find("destination address setting error (0x0501)"), std::string::npos)
        << text.err;
    EXPECT_NE(text.err.find("relay error: the router at network 1 node 1"), std::string::npos)
        << text.err;
    auto json = fins_cli(plant, {"--dest", "9.5.0", "--json", "read", "D10"});
    EXPECT_EQ(json.exit_code, 4);
    EXPECT_NE(json.out.find(R"("relay_error":{"network":1,"node":1})"), std::string::npos)
        << json.out;
    auto raw = fins_cli(plant, {"--dest", "9.5.0", "raw", "0101", "82000A00", "0001"});
    EXPECT_NE(raw.out.find("end code 8501"), std::string::npos) << raw.out;
    EXPECT_NE(raw.out.find("[relay error at network 1 node 1]"), std::string::npos) << raw.out;
}

}  // namespace
}  // namespace fins::test
