// The TOML contract (config.hpp): every bad input is one "file:line:col: message".
#include "bridge/config.hpp"

#include <gtest/gtest.h>

#include "bridge_test_support.hpp"

namespace fins::bridge {
namespace {

using test::one_group;
using test::parse_error;
using test::parse_ok;

TEST(BridgeConfig, TheIssueExampleLoads) {
    auto c = parse_ok(R"([bridge]
instance = "edge-1"
failover_s = 10
[mqtt]
host = "127.0.0.1"
topic_prefix = "finskit"
[[plc]]
name = "press1"
host = "127.0.0.1"
[[plc.group]]
name = "fast"
interval_ms = 100
publish = "change"
tags = [ { name = "speed", address = "D100", type = "int16" },
         { name = "run",   address = "CIO0.00", type = "bool" },
         { name = "temp",  address = "D200", type = "float", writable = true } ]
)");
    ASSERT_EQ(c.plcs.size(), 1u);
    EXPECT_EQ(c.instance, "test");  // --instance wins
    EXPECT_EQ(c.mqtt.brokers[0].host, "127.0.0.1");
    EXPECT_EQ(c.mqtt.brokers[0].port, 1883);
    EXPECT_EQ(c.mqtt.client_id, "fins-bridge-test");
    const auto& g = c.plcs[0].groups[0];
    EXPECT_EQ(g.interval.count(), 100);
    ASSERT_EQ(g.tags.size(), 3u);
    EXPECT_EQ(g.tags[1].type, TagType::bits);
    EXPECT_EQ(g.tags[1].read_start, (MemoryAddress{0xB0, 0, 0}));
    EXPECT_TRUE(g.tags[2].writable);
    EXPECT_EQ(g.tags[2].words, 2u);
}

TEST(BridgeConfig, UnknownKeyNamesItsPlace) {
    EXPECT_EQ(parse_error("[mqtt]\nhost = \"h\"\nhots = 1\n" +
                          one_group("{name=\"a\",address=\"D0\",type=\"int16\"}")),
              "t.toml:3:1: unknown key 'hots' in [mqtt]");
    EXPECT_EQ(parse_error(one_group("{name=\"a\",address=\"D0\",type=\"int16\",wrtable=true}")),
              "t.toml:6:45: unknown key 'wrtable' in a tag");
}

TEST(BridgeConfig, BadNames) {
    EXPECT_NE(
        parse_error(one_group("{name=\"a b\",address=\"D0\",type=\"int16\"}")).find("t.toml:6:"),
        std::string::npos);
    const std::string two =
        one_group("{name=\"a\",address=\"D0\",type=\"int16\"}") +
        "[[plc]]\nname = \"p\"\nhost = "
        "\"h\"\n[[plc.group]]\nname=\"g\"\ntags=[{name=\"a\",address=\"D0\",type=\"int16\"}]\n";
    EXPECT_EQ(parse_error(two), "t.toml:8:8: duplicate PLC name 'p'");
    EXPECT_EQ(parse_error(one_group("{name=\"a\",address=\"D0\",type=\"int16\"},{name=\"a\","
                                    "address=\"D1\",type=\"int16\"}")),
              "t.toml:6:52: duplicate tag name 'a' in this PLC");
}

TEST(BridgeConfig, BadAddressesAndTypes) {
    EXPECT_NE(parse_error(one_group("{name=\"a\",address=\"Q100\",type=\"int16\"}"))
                  .find("t.toml:6:27: address 'Q100'"),
              std::string::npos);
    EXPECT_EQ(parse_error(one_group("{name=\"a\",address=\"D0\",type=\"int64\"}")),
              "t.toml:6:37: type 'int64' is not bool, int16, uint16, int32, uint32, float, "
              "double, bcd, bcd32 or string");
    EXPECT_NE(parse_error(one_group("{name=\"a\",address=\"D100.1\",type=\"int16\"}"))
                  .find("type must be bool"),
              std::string::npos);
    EXPECT_NE(parse_error(one_group("{name=\"a\",address=\"D100\",type=\"bool\"}"))
                  .find("a bool needs a bit"),
              std::string::npos);
}

TEST(BridgeConfig, AddressBeyondTheModel) {
    // CJ1M-CPU13 has no EM at all; the CJ2H has banks 0-18 (W342 5-2-2).
    auto e = parse_error(
        "[[plc]]\nname=\"p\"\nhost=\"h\"\nmodel=\"cj1m\"\n[[plc.group]]\nname=\"g\"\n"
        "tags=[{name=\"a\",address=\"E0_100\",type=\"int16\"}]\n");
    EXPECT_EQ(e.rfind("t.toml:7:25: ", 0), 0u) << e;
    parse_ok(
        "[[plc]]\nname=\"p\"\nhost=\"h\"\n[[plc.group]]\nname=\"g\"\n"
        "tags=[{name=\"a\",address=\"E0_100\",type=\"int16\"}]\n");
}

TEST(BridgeConfig, ATagThatDoesNotFitAFrame) {
    auto e = parse_error(one_group("{name=\"s\",address=\"D0\",type=\"string\",length=2000}"));
    EXPECT_NE(e.find("more than one frame"), std::string::npos) << e;
    auto end = parse_error(one_group("{name=\"a\",address=\"D32767\",type=\"int32\"}"));
    EXPECT_NE(end.find("does not fit in its area"), std::string::npos) << end;
}

TEST(BridgeConfig, WritableTagsMustBeWritable) {
    auto e = parse_error(one_group("{name=\"a\",address=\"A100\",type=\"int16\",writable=true}"));
    EXPECT_NE(e.find("read-only"), std::string::npos) << e;
    auto t = parse_error(one_group("{name=\"a\",address=\"T5\",type=\"bool\",writable=true}"));
    EXPECT_NE(t.find("cannot be written"), std::string::npos) << t;
}

TEST(BridgeConfig, TomlSyntaxErrorsHavePositions) {
    EXPECT_EQ(parse_error("[mqtt\n").rfind("t.toml:1:", 0), 0u);
}

TEST(BridgeConfig, NoPlcIsAnError) {
    EXPECT_EQ(parse_error("[mqtt]\nhost=\"h\"\n"), "t.toml:1:1: no [[plc]]: nothing to poll");
}

TEST(BridgeConfig, DestAndBrokers) {
    auto c = parse_ok(
        "[mqtt]\nhosts=[\"a:1884\",\"b\"]\n[[plc]]\nname=\"p\"\nhost=\"h\"\ndest=\"1.2.0\"\n"
        "[[plc.group]]\nname=\"g\"\ntags=[{name=\"a\",address=\"D0\",type=\"int16\"}]\n");
    ASSERT_EQ(c.mqtt.brokers.size(), 2u);
    EXPECT_EQ(c.mqtt.brokers[0].port, 1884);
    EXPECT_EQ(c.mqtt.brokers[1].host, "b");
    EXPECT_EQ(c.plcs[0].dest, (NodeAddress{1, 2, 0}));
    EXPECT_NE(
        parse_error("[[plc]]\nname=\"p\"\nhost=\"h\"\ndest=\"1.2\"\n[[plc.group]]\nname=\"g\"\n"
                    "tags=[{name=\"a\",address=\"D0\",type=\"int16\"}]\n")
            .find("net.node.unit"),
        std::string::npos);
}

TEST(BridgeConfig, MinAboveMaxIsAnErrorAtMin) {
    EXPECT_EQ(parse_error(one_group(
                  "{name=\"a\",address=\"D0\",type=\"int16\",writable=true,min=10,max=5}")),
              "t.toml:6:63: min 10 is above max 5: no value could be written");
    // min == max is one value: allowed.
    parse_ok(one_group("{name=\"a\",address=\"D0\",type=\"int16\",writable=true,min=5,max=5}"));
}

TEST(BridgeConfig, EmptyHostsAreErrors) {
    EXPECT_EQ(parse_error("[mqtt]\nhost = \"\"\n" +
                          one_group("{name=\"a\",address=\"D0\",type=\"int16\"}")),
              "t.toml:2:8: host must not be empty");
    EXPECT_EQ(parse_error("[[plc]]\nname = \"p\"\nhost = \"\"\n[[plc.group]]\nname = \"g\"\n"
                          "tags = [{name=\"a\",address=\"D0\",type=\"int16\"}]\n"),
              "t.toml:3:8: host must not be empty");
}

TEST(BridgeConfig, ATlsFileThatCannotBeReadIsAnErrorAtItsKey) {
    EXPECT_EQ(parse_error("[mqtt]\nca_file = \"/nonexistent/ca.crt\"\n" +
                          one_group("{name=\"a\",address=\"D0\",type=\"int16\"}")),
              "t.toml:2:11: ca_file '/nonexistent/ca.crt' cannot be read");
}

TEST(BridgeConfig, PortAloneUsesTheDefaultHost) {
    auto c =
        parse_ok("[mqtt]\nport = 1884\n" + one_group("{name=\"a\",address=\"D0\",type=\"int16\"}"));
    ASSERT_EQ(c.mqtt.brokers.size(), 1u);
    EXPECT_EQ(c.mqtt.brokers[0].host, "127.0.0.1");
    EXPECT_EQ(c.mqtt.brokers[0].port, 1884);
    // With hosts, port is the default port of the entries without one.
    c = parse_ok("[mqtt]\nport = 1884\nhosts = [\"a\", \"b:1999\"]\n" +
                 one_group("{name=\"a\",address=\"D0\",type=\"int16\"}"));
    ASSERT_EQ(c.mqtt.brokers.size(), 2u);
    EXPECT_EQ(c.mqtt.brokers[0].port, 1884);
    EXPECT_EQ(c.mqtt.brokers[1].port, 1999);
}

TEST(BridgeConfig, TsSkew) {
    EXPECT_EQ(parse_ok(one_group("{name=\"a\",address=\"D0\",type=\"int16\"}")).write.ts_skew,
              std::chrono::seconds(5));
    EXPECT_EQ(parse_ok("[write]\nts_skew_s = 30\n" +
                       one_group("{name=\"a\",address=\"D0\",type=\"int16\"}"))
                  .write.ts_skew,
              std::chrono::seconds(30));
}

}  // namespace
}  // namespace fins::bridge
