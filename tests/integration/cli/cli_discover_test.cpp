// `fins discover` on loopback: two finsd instances bound to 127.0.0.2 and 127.0.0.5 on
// one port (Linux routes all of 127/8 to lo), the sweep over ranges and CIDR blocks
// around them lists exactly those two, with node, model and version from 05 01 (W342
// 5-3-15), in the order the range names the hosts. Hosts where nothing listens cost one timeout
// each, in parallel.
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

class CliDiscover : public ::testing::Test {
  protected:
    void SetUp() override {
        a_ = std::make_unique<Finsd>(std::vector<std::string>{"--bind", "127.0.0.2"});
        ASSERT_TRUE(a_->started()) << a_->result().err;
        port_ = std::to_string(a_->port());
        // The same port on another loopback address: finsd's --port 0 is only for the first.
        b_ =
            std::make_unique<Finsd>(std::vector<std::string>{"--bind", "127.0.0.5", "--node", "50"},
                                    FinsdOptions{.port = a_->port()});
        ASSERT_TRUE(b_->started()) << b_->result().err;
        ASSERT_EQ(b_->port(), a_->port());
    }
    RunResult discover(std::vector<std::string> args) {
        std::vector<std::string> v{fins_bin, "--port", port_, "--timeout", "0.5", "discover"};
        v.insert(v.end(), args.begin(), args.end());
        return run(v);
    }
    nlohmann::json discover_json(std::vector<std::string> args, int expected_exit = 0) {
        args.push_back("--json");
        const auto r = discover(args);
        EXPECT_EQ(r.exit_code, expected_exit) << r.out << r.err;
        return nlohmann::json::parse(r.out, nullptr, false);
    }

    std::unique_ptr<Finsd> a_;
    std::unique_ptr<Finsd> b_;
    std::string port_;
};

TEST_F(CliDiscover, W342_5_3_15_ListsTheNodesThatAnswerInRangeOrder) {
    const auto doc = discover_json({"--hosts", "127.0.0.1-127.0.0.9"});
    EXPECT_EQ(doc["hosts"], 9);
    ASSERT_EQ(doc["nodes"].size(), 2u) << doc.dump();
    EXPECT_EQ(doc["nodes"][0]["host"], "127.0.0.2");
    // finsd --bind 127.0.0.2: node 2, the last octet on loopback too (W420 5-2)
    EXPECT_EQ(doc["nodes"][0]["node"], "0.2.0");
    EXPECT_EQ(doc["nodes"][0]["model"], "CJ2H-CPU68-EIP");
    EXPECT_FALSE(doc["nodes"][0]["version"].get<std::string>().empty());
    EXPECT_EQ(doc["nodes"][1]["host"], "127.0.0.5");
    EXPECT_EQ(doc["nodes"][1]["node"], "0.50.0");

    // The same with the last octet only, one request at a time, and in text.
    const auto text = discover({"--hosts", "127.0.0.1-9", "--parallel", "1"});
    EXPECT_EQ(text.exit_code, 0) << text.err;
    std::istringstream lines(text.out);
    std::string first, second, summary;
    std::getline(lines, first);
    std::getline(lines, second);
    std::getline(lines, summary);
    EXPECT_EQ(first.rfind("127.0.0.2  ", 0), 0u) << text.out;
    EXPECT_NE(first.find("CJ2H-CPU68-EIP"), std::string::npos) << text.out;
    EXPECT_EQ(second.rfind("127.0.0.5  ", 0), 0u) << text.out;
    EXPECT_EQ(summary, "2 of 9 hosts answered (UDP port " + port_ + ")");
}

TEST_F(CliDiscover, CidrBlocksSkipNetworkAndBroadcastAndListsCombine) {
    const auto block = discover_json({"--hosts", "127.0.0.0/29"});  // .1 - .6
    EXPECT_EQ(block["hosts"], 6);
    EXPECT_EQ(block["nodes"].size(), 2u);
    // In the order the list names them.
    const auto list = discover_json({"--hosts", "127.0.0.5,127.0.0.2/32"});
    EXPECT_EQ(list["hosts"], 2);
    ASSERT_EQ(list["nodes"].size(), 2u);
    EXPECT_EQ(list["nodes"][0]["host"], "127.0.0.5");
    EXPECT_EQ(list["nodes"][1]["host"], "127.0.0.2");
}

TEST_F(CliDiscover, NobodyAnsweringExits3) {
    const auto r = discover({"--hosts", "127.0.0.6-8", "--retries", "1"});
    EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("discover 127.0.0.6-8"), std::string::npos) << r.err;
}

TEST_F(CliDiscover, Newcomer13_NobodyAnsweringWithJsonPrintsAnEmptyListAndExits3) {
    const auto doc = discover_json({"--hosts", "127.0.0.6-8", "--retries", "0"}, 3);
    EXPECT_EQ(doc["hosts"], 3) << doc.dump();
    ASSERT_TRUE(doc["nodes"].is_array()) << doc.dump();
    EXPECT_TRUE(doc["nodes"].empty()) << doc.dump();
    EXPECT_EQ(doc["port"], std::stoi(port_));
}

TEST_F(CliDiscover, BadOrOversizedRangesAreUsageErrors) {
    for (const auto& hosts : {"10.0.0.0/16", "10.0.0.0/21", "127.0.0.9-3", "127.0.0.1-300",
                              "127.0.0", "example.com", "127.0.0.1/33", "10.0.0.0-10.0.8.0", ""}) {
        const auto r = discover({"--hosts", hosts});
        EXPECT_EQ(r.exit_code, 2) << hosts << ": " << r.err;
    }
    const auto tcp = run({fins_bin, "--tcp", "discover", "--hosts", "127.0.0.2"});
    EXPECT_EQ(tcp.exit_code, 2);
}

}  // namespace
}  // namespace fins::test
