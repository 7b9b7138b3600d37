// Ownership without a broker: rendezvous hashing's promises (one owner, balance, minimal
// movement) and the membership rules (claim nothing before the own status comes back, a Will
// hands the dead member's PLCs to the others, junk is not a member).
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "bridge/cluster/membership.hpp"
#include "bridge/cluster/rendezvous.hpp"

namespace cl = fins::bridge::cluster;

namespace {

std::vector<std::string> plcs(int n) {
    std::vector<std::string> v;
    for (int i = 0; i < n; ++i)
        v.push_back("plc" + std::to_string(i));
    return v;
}

std::map<std::string, std::string> assign(const std::vector<std::string>& members,
                                          const std::vector<std::string>& names) {
    std::map<std::string, std::string> out;
    for (const auto& p : names)
        out[p] = members[cl::rendezvous_owner(members, p)];
    return out;
}

constexpr const char* online = R"({"state":"online","instance":"x"})";
constexpr const char* offline = R"({"state":"offline"})";

}  // namespace

TEST(ClusterRendezvous, WeightIsFixedAcrossBuilds) {
    // Pinned: instances built by different compilers must pick the same owner.
    EXPECT_EQ(cl::rendezvous_weight("edge-1", "press1"), cl::rendezvous_weight("edge-1", "press1"));
    EXPECT_NE(cl::rendezvous_weight("ab", "c"), cl::rendezvous_weight("a", "bc"));
    static const std::uint64_t pinned = cl::rendezvous_weight("edge-1", "press1");
    EXPECT_EQ(pinned, 0xdaddf3211356537eULL) << std::hex << pinned;
}

TEST(ClusterRendezvous, OwnerIsIndependentOfMemberOrderAndEmptyHasNone) {
    const std::vector<std::string> a{"edge-1", "edge-2", "edge-3"};
    const std::vector<std::string> b{"edge-3", "edge-1", "edge-2"};
    for (const auto& p : plcs(200))
        EXPECT_EQ(a[cl::rendezvous_owner(a, p)], b[cl::rendezvous_owner(b, p)]);
    EXPECT_EQ(cl::rendezvous_owner(std::vector<std::string>{}, "x"), 0U);
}

TEST(ClusterRendezvous, SharesAreBalanced) {
    const std::vector<std::string> m{"edge-1", "edge-2", "edge-3"};
    std::map<std::string, int> count;
    for (const auto& [plc, owner] : assign(m, plcs(3000)))
        ++count[owner];
    for (const auto& name : m) {
        EXPECT_GT(count[name], 850) << name;  // 1000 expected; +-15 %
        EXPECT_LT(count[name], 1150) << name;
    }
}

TEST(ClusterRendezvous, ADeathMovesOnlyTheDeadMembersPlcs) {
    const auto names = plcs(1000);
    const auto before = assign({"a", "b", "c"}, names);
    const auto after = assign({"a", "c"}, names);
    int moved = 0;
    for (const auto& p : names) {
        if (before.at(p) != "b") {
            EXPECT_EQ(before.at(p), after.at(p)) << p;
        } else {
            ++moved;
        }
    }
    EXPECT_GT(moved, 0);
}

TEST(ClusterRendezvous, AJoinMovesPlcsOnlyToTheNewMember) {
    const auto names = plcs(1000);
    const auto before = assign({"a", "b"}, names);
    const auto after = assign({"a", "b", "c"}, names);
    for (const auto& p : names) {
        if (before.at(p) != after.at(p)) {
            EXPECT_EQ(after.at(p), "c") << p;
        }
    }
}

TEST(ClusterMembership, ClaimsNothingUntilItsOwnOnlineComesBack) {
    cl::Membership m("edge-1");
    EXPECT_FALSE(m.owns("press1"));
    EXPECT_TRUE(m.on_status("edge-2", online));  // a retained status from the broker
    EXPECT_FALSE(m.synced());
    EXPECT_FALSE(m.owns("press1"));
    EXPECT_EQ(m.owner("press1"), "edge-2");
    // Before joining it already knows which PLCs will be its own (retained commands).
    std::vector<bool> future;
    for (const auto& p : plcs(100))
        future.push_back(m.owns_once_joined(p));
    EXPECT_TRUE(m.on_status("edge-1", online));
    EXPECT_TRUE(m.synced());
    for (std::size_t i = 0; i < 100; ++i)
        EXPECT_EQ(m.owns_once_joined(plcs(100)[i]), future[i]);
    for (std::size_t i = 0; i < 100; ++i)
        EXPECT_EQ(m.owns(plcs(100)[i]), future[i]);
    EXPECT_EQ(m.members(), (std::vector<std::string>{"edge-1", "edge-2"}));
    int mine = 0;
    for (const auto& p : plcs(100))
        mine += m.owns(p) ? 1 : 0;
    EXPECT_GT(mine, 0);
    EXPECT_LT(mine, 100);
}

TEST(ClusterMembership, AWillHandsTheDeadMembersPlcsOver) {
    cl::Membership m1("edge-1");
    cl::Membership m2("edge-2");
    for (auto* m : {&m1, &m2}) {
        m->on_status("edge-1", online);
        m->on_status("edge-2", online);
    }
    for (const auto& p : plcs(100))
        EXPECT_NE(m1.owns(p), m2.owns(p)) << p;    // exactly one owner
    EXPECT_TRUE(m1.on_status("edge-2", offline));  // edge-2's Will
    for (const auto& p : plcs(100))
        EXPECT_TRUE(m1.owns(p)) << p;
    EXPECT_FALSE(m1.on_status("edge-2", offline));  // no change, no re-evaluation
    EXPECT_EQ(m1.changes(), 3U);
}

TEST(ClusterMembership, JunkAndClearedStatusesAreNotMembers) {
    cl::Membership m("edge-1");
    m.on_status("edge-1", online);
    EXPECT_FALSE(m.on_status("x", "not json"));
    EXPECT_FALSE(m.on_status("y", R"({"state":"maybe"})"));
    EXPECT_FALSE(m.on_status("z", R"(["online"])"));
    EXPECT_TRUE(m.on_status("w", online));
    EXPECT_TRUE(m.on_status("w", ""));      // retained status deleted
    EXPECT_FALSE(m.on_status("", online));  // no topic names it (fuzz_membership)
    EXPECT_EQ(m.members(), std::vector<std::string>{"edge-1"});
}

TEST(ClusterMembership, TheTableIsBoundedAndForgetsTheOffline) {
    cl::Membership m("edge-1");
    m.on_status("edge-1", online);
    for (std::size_t i = 0; i < 10 * cl::max_members; ++i)
        m.on_status("x" + std::to_string(i), online);
    // Any client of the broker can publish a status: at most max_members names, self apart.
    EXPECT_EQ(m.known(), cl::max_members + 1);
    EXPECT_EQ(m.refused(), 10 * cl::max_members - cl::max_members);
    EXPECT_EQ(m.members().size(), cl::max_members + 1);
    // Offline names are forgotten: their room is free again.
    for (std::size_t i = 0; i < cl::max_members; ++i)
        m.on_status("x" + std::to_string(i), offline);
    EXPECT_EQ(m.known(), 1u);
    EXPECT_EQ(m.members(), std::vector<std::string>{"edge-1"});
    EXPECT_TRUE(m.on_status("late", online));
    EXPECT_EQ(m.members(), (std::vector<std::string>{"edge-1", "late"}));
    // An offline status of a name never seen takes no room.
    for (int i = 0; i < 1000; ++i)
        EXPECT_FALSE(m.on_status("gone" + std::to_string(i), offline));
    EXPECT_EQ(m.known(), 2u);
}

TEST(ClusterMembership, ItsOwnStatusIsHeardAtTheBound) {
    cl::Membership m("edge-1");
    for (std::size_t i = 0; i < cl::max_members + 5; ++i)
        m.on_status("x" + std::to_string(i), online);
    EXPECT_TRUE(m.on_status("edge-1", online));
    EXPECT_TRUE(m.synced());
    EXPECT_EQ(m.members().size(), cl::max_members + 1);
}

TEST(ClusterMembership, LosingTheBrokerOrSeeingItsOwnWillGivesEverythingUp) {
    cl::Membership m("edge-1");
    m.on_status("edge-1", online);
    EXPECT_TRUE(m.owns("press1"));
    EXPECT_TRUE(m.connection_lost());
    EXPECT_FALSE(m.owns("press1"));
    EXPECT_FALSE(m.connection_lost());
    EXPECT_TRUE(m.on_status("edge-1", online));  // reconnected: synced again
    EXPECT_TRUE(m.owns("press1"));
    // The broker delivers the Will of our previous connection: we were replaced meanwhile.
    EXPECT_TRUE(m.on_status("edge-1", offline));
    EXPECT_FALSE(m.owns("press1"));
}

TEST(ClusterMembership, StatusTopics) {
    EXPECT_EQ(cl::status_topic("finskit", "edge-1"), "finskit/$bridge/edge-1/status");
    EXPECT_EQ(cl::status_filter("finskit"), "finskit/$bridge/+/status");
    EXPECT_EQ(cl::status_topic_instance("finskit", "finskit/$bridge/edge-1/status"), "edge-1");
    EXPECT_FALSE(cl::status_topic_instance("finskit", "finskit/$bridge//status"));
    EXPECT_FALSE(cl::status_topic_instance("finskit", "finskit/$bridge/a/b/status"));
    EXPECT_FALSE(cl::status_topic_instance("finskit", "other/$bridge/edge-1/status"));
    EXPECT_FALSE(cl::status_topic_instance("finskit", "finskit/press1/status"));
}

TEST(ClusterMembership, KeepaliveMeetsFailover) {
    EXPECT_EQ(cl::keepalive_for_failover(10), 6);  // Will after 9 s, + 1 s of rounding
    EXPECT_EQ(cl::keepalive_for_failover(31), 20);
    EXPECT_EQ(cl::keepalive_for_failover(3), 5);  // libmosquitto's minimum
    for (int f = 9; f < 100; ++f)
        EXPECT_LE(cl::keepalive_for_failover(f) * 3 / 2 + 1, f) << f;
}
