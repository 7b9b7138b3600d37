// A Sparkplug and a JSON instance on one topic_prefix are not one cluster: a member's payload
// kind is part of its identity, an instance of the other kind is no member (each kind's
// instances share the PLCs among themselves, and each PLC appears in both forms).
#include <gtest/gtest.h>

#include "bridge/cluster/cluster_ownership.hpp"

namespace cl = fins::bridge::cluster;

namespace {

constexpr const char* json_online = R"({"state":"online","instance":"x"})";
constexpr const char* sparkplug_online =
    R"({"state":"online","instance":"x","payload":"sparkplug","edge_node":"spBv1.0/t/NBIRTH/x"})";

}  // namespace

TEST(SparkplugCluster, AnInstanceOfTheOtherPayloadKindIsNoMember) {
    cl::ClusterOwnership sparkplug("b", "t", "sparkplug");
    EXPECT_TRUE(sparkplug.on_message("t/$bridge/b/status", sparkplug_online));  // self: synced
    EXPECT_TRUE(sparkplug.on_message("t/$bridge/a/status", json_online));
    EXPECT_TRUE(sparkplug.on_message("t/$bridge/c/status", sparkplug_online));
    EXPECT_EQ(sparkplug.membership().members(), (std::vector<std::string>{"b", "c"}));

    cl::ClusterOwnership json("a", "t", "json");
    EXPECT_TRUE(json.on_message("t/$bridge/a/status", json_online));
    EXPECT_TRUE(json.on_message("t/$bridge/b/status", sparkplug_online));
    EXPECT_TRUE(json.on_message("t/$bridge/d/status", R"({"state":"online","payload":"json"})"));
    EXPECT_EQ(json.membership().members(), (std::vector<std::string>{"a", "d"}));
    // The Sparkplug instance owns no PLC among the JSON ones.
    for (const char* plc : {"press1", "press2", "press3", "press4", "press5", "press6"})
        EXPECT_NE(json.membership().owner(plc), "b") << plc;
    EXPECT_FALSE(json.on_message("t/other", json_online));  // not membership
}
