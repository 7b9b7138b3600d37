// A PLC online whose every tag fails with an end code (bridge/poll/tag_failures.hpp): its
// status turns "failing" with the dest hint once every group's last cycle failed, and
// "online" again at the first value; timeouts (the poller's offline path) do not count.
#include "bridge/poll/tag_failures.hpp"

#include <gtest/gtest.h>

#include "bridge/bridge_test_support.hpp"
#include "bridge/json_payload.hpp"

namespace fins::bridge {
namespace {

std::vector<TagSample> samples(std::size_t n, std::error_code error) {
    std::vector<TagSample> s(n);
    for (auto& t : s)
        t.error = error;
    return s;
}

TEST(TagFailures, EveryGroupFailingWithEndCodesIsFailingUntilAValue) {
    auto c = test::parse_ok(
        "[[plc]]\nname = \"p\"\nhost = \"127.0.0.5\"\n"
        "[[plc.group]]\nname = \"a\"\ntags = [{name=\"x\",address=\"D0\",type=\"int16\"},"
        "{name=\"y\",address=\"D1\",type=\"int16\"}]\n"
        "[[plc.group]]\nname = \"b\"\ntags = [{name=\"z\",address=\"D9\",type=\"int16\"}]\n");
    ASSERT_EQ(c.plcs.size(), 1u);
    const Plc& plc = c.plcs[0];
    const auto e0201 = make_error_code(EndCode::destination_node_not_in_network);
    const NodeAddress to{0, 5, 0};
    TagFailures f;
    PlcStatus online{&plc, true, "", 1, false};
    auto bad = samples(2, e0201);
    auto bad_b = samples(1, e0201);
    // Group a alone fails: group b has not told yet.
    EXPECT_FALSE(f.cycle({&plc, &plc.groups[0], bad, 2, true}, online, to));
    // Timeouts are the poller's to report (it goes offline): no news.
    auto timeouts = samples(1, make_error_code(ClientError::timeout));
    EXPECT_FALSE(f.cycle({&plc, &plc.groups[1], timeouts, 3, true}, online, to));
    auto failing = f.cycle({&plc, &plc.groups[1], bad_b, 4, true}, online, to);
    ASSERT_TRUE(failing);
    EXPECT_TRUE(failing->online);
    EXPECT_TRUE(failing->failing);
    EXPECT_EQ(failing->ts_ms, 4);
    EXPECT_EQ(failing->last_error,
              "every tag fails: " + error_text(e0201) +
                  "; requests go to node 0.5.0 (the last number of its IP address): if the "
                  "PLC is another node, set dest = \"NET.NODE.UNIT\" for plc \"p\" (`fins "
                  "--host 127.0.0.5 probe` tells its node)");
    // Said once, not per cycle.
    EXPECT_FALSE(f.cycle({&plc, &plc.groups[0], bad, 5, true}, *failing, to));
    // One value: online again.
    auto one_good = samples(2, e0201);
    one_good[1].error = {};
    auto back = f.cycle({&plc, &plc.groups[0], one_good, 6, true}, *failing, to);
    ASSERT_TRUE(back);
    EXPECT_TRUE(back->online);
    EXPECT_FALSE(back->failing);
    EXPECT_TRUE(back->last_error.empty());
    // An offline PLC is the poller's: nothing.
    PlcStatus offline{&plc, false, "timeout", 7, false};
    EXPECT_FALSE(f.cycle({&plc, &plc.groups[0], bad, 8, true}, offline, to));
}

TEST(TagFailures, JsonStatusSaysFailing) {
    auto c = test::parse_ok(test::one_group(R"({name="a",address="D0",type="int16"})"));
    JsonPayload json("pre", "edge");
    std::vector<Message> out;
    json.status({&c.plcs[0], true, "every tag fails: ...", 9, true},
                [&](Message&& m) { out.push_back(std::move(m)); });
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].topic, "pre/p/status");
    EXPECT_TRUE(out[0].retain);
    EXPECT_EQ(nlohmann::json::parse(out[0].payload)["state"], "failing") << out[0].payload;
    EXPECT_EQ(nlohmann::json::parse(out[0].payload)["error"], "every tag fails: ...");
}

}  // namespace
}  // namespace fins::bridge
