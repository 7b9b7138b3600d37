// finsd's FINS/TCP limit keys and flags (README "FINS/TCP identity and limits"): the
// defaults, the [network] keys, their ranges and the flags that override them.
#include "finsd/config.hpp"

#include <gtest/gtest.h>

namespace fins::finsd {
namespace {

TEST(FinsdTcpLimits, DefaultsKeysRangesAndFlags) {
    Settings s;
    EXPECT_EQ(s.tcp_handshake_timeout, 10u);
    EXPECT_EQ(s.tcp_frame_timeout, 10u);
    EXPECT_EQ(s.tcp_idle_timeout, 300u);
    EXPECT_EQ(s.tcp_keepalive, 60u);
    EXPECT_EQ(s.tcp_max_pending, 16u);
    ASSERT_TRUE(load_config_text(R"([network]
tcp_handshake_timeout = 3
tcp_frame_timeout = 4
tcp_idle_timeout = 0
tcp_keepalive = 0
tcp_max_pending = 5
)",
                                 "t.toml", s));
    EXPECT_EQ(s.tcp_handshake_timeout, 3u);
    EXPECT_EQ(s.tcp_frame_timeout, 4u);
    EXPECT_EQ(s.tcp_idle_timeout, 0u);
    EXPECT_EQ(s.tcp_keepalive, 0u);
    EXPECT_EQ(s.tcp_max_pending, 5u);

    Settings t;
    auto r = load_config_text("[network]\ntcp_handshake_timeout = 0\n", "t.toml", t);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:2:1: network.tcp_handshake_timeout: 0 is not 1-3600");
    r = load_config_text("[network]\ntcp_max_pending = 0\n", "t.toml", t);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:2:1: network.tcp_max_pending: 0 is not 1-1024");

    Overrides o;
    o.tcp_idle_timeout = 30;
    o.tcp_keepalive = 15;
    o.tcp_max_pending = 8;
    ASSERT_TRUE(apply_overrides(o, s));
    EXPECT_EQ(s.tcp_idle_timeout, 30u);
    EXPECT_EQ(s.tcp_keepalive, 15u);
    EXPECT_EQ(s.tcp_max_pending, 8u);
    EXPECT_EQ(s.tcp_frame_timeout, 4u);
}

}  // namespace
}  // namespace fins::finsd
