// config::read_table (src/config/schema.hpp): the one wording of unknown, mistyped and
// missing keys, file order, and what a reader's own failure does to the walk.
#include "config/schema.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace fins::config {
namespace {

toml::table parse(std::string_view text) {
    return toml::parse(text, std::string_view("t.toml"));
}

TEST(ConfigSchema, StoresDeclaredKeys) {
    const auto t = parse("name = \"a\"\nudp = true\nport = 9600\nscale = 2\n");
    std::string name;
    bool udp = false;
    std::uint16_t port = 0;
    double scale = 0;
    const auto r = read_table(t, {"t.toml", ""},
                              {text_key("name", name), flag_key("udp", udp),
                               integer_key("port", port, 0, 65535), number_key("scale", scale)});
    ASSERT_TRUE(r) << r.error();
    EXPECT_EQ(name, "a");
    EXPECT_TRUE(udp);
    EXPECT_EQ(port, 9600);
    EXPECT_EQ(scale, 2.0);  // an integer is a number
}

TEST(ConfigSchema, OptionalsAreSetOnlyWhenGiven) {
    const auto t = parse("bank = 3\n");
    std::optional<std::uint8_t> bank;
    std::optional<bool> cassette;
    ASSERT_TRUE(read_table(t, {"t.toml", ""},
                           {integer_key("bank", bank, 0, 24), flag_key("cassette", cassette)}));
    EXPECT_EQ(bank, 3);
    EXPECT_FALSE(cassette.has_value());
}

TEST(ConfigSchema, UnknownKeyNamesItsPathAndPosition) {
    const auto t = parse("[network]\nnode = 1\nspeed = 1\n");
    std::uint8_t node = 0;
    const auto r = read_table(*t["network"].as_table(), {"t.toml", "network"},
                              {integer_key("node", node, 0, 254)});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:3:1: network.speed: unknown key");
    EXPECT_EQ(node, 1);  // what came before was read
}

TEST(ConfigSchema, AtTheRootTheKeyIsThePath) {
    const auto t = parse("\nprofle = 1\n");
    const auto r = read_table(t, {"t.toml", ""}, {{"profile", Type::string, {}}});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:2:1: profle: unknown key");
}

TEST(ConfigSchema, WrongTypeAtTheValueOrTheKey) {
    const auto t = parse("node = \"ten\"\n");
    std::uint8_t node = 0;
    const auto at_value = read_table(t, {"t.toml", "plc[0]"}, {integer_key("node", node, 0, 254)});
    ASSERT_FALSE(at_value);
    EXPECT_EQ(at_value.error(), "t.toml:1:8: plc[0].node: must be an integer");
    const auto at_key =
        read_table(t, {"t.toml", "network", At::key}, {integer_key("node", node, 0, 254)});
    ASSERT_FALSE(at_key);
    EXPECT_EQ(at_key.error(), "t.toml:1:1: network.node: must be an integer");
}

TEST(ConfigSchema, EveryTypeHasItsMessage) {
    const auto t = parse("v = 1.5\n");
    const Type types[] = {Type::string, Type::integer, Type::boolean, Type::table, Type::array};
    for (const Type type : types) {
        const auto r = read_table(t, {"t.toml", ""}, {{"v", type, {}}});
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error(), "t.toml:1:5: v: " + std::string(must_be(type)));
    }
    EXPECT_TRUE(read_table(t, {"t.toml", ""}, {{"v", Type::number, {}}}));
    EXPECT_TRUE(read_table(t, {"t.toml", ""}, {{"v", Type::any, {}}}));
    EXPECT_EQ(must_be(Type::boolean), "must be true or false");
}

TEST(ConfigSchema, IntegerOutOfRange) {
    const auto t = parse("port = 70000\n");
    std::uint16_t port = 1;
    const auto r = read_table(t, {"t.toml", "network"}, {integer_key("port", port, 0, 65535)});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:1:8: network.port: 70000 is not 0-65535");
    EXPECT_EQ(port, 1);
}

TEST(ConfigSchema, MissingRequiredKeyAfterTheWalk) {
    const auto t = parse("[[plc]]\nprofile = \"cj2h\"\n");
    const auto& plc = *(*t["plc"].as_array())[0].as_table();
    std::string name, profile;
    const auto r = read_table(plc, {"t.toml", "plc[0]"},
                              {{"name", Type::string, {}, true}, text_key("profile", profile)});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:1:1: plc[0]: name: missing");
    EXPECT_EQ(profile, "cj2h");
}

TEST(ConfigSchema, FileOrderNotKeyOrder) {
    // toml::table sorts by name; the walk follows the file: the first problem is line 1's.
    const auto t = parse("zeta = 1\nalpha = 2\n");
    std::vector<std::string> seen;
    const Reader note = [&](const Entry& e) -> Expected<void> {
        seen.push_back(e.path);
        return {};
    };
    ASSERT_TRUE(
        read_table(t, {"t.toml", "s"}, {{"alpha", Type::any, note}, {"zeta", Type::any, note}}));
    EXPECT_EQ(seen, (std::vector<std::string>{"s.zeta", "s.alpha"}));
    const auto r = read_table(t, {"t.toml", ""}, {});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:1:1: zeta: unknown key");
}

TEST(ConfigSchema, ReaderFailureEndsTheWalk) {
    const auto t = parse("a = 1\nb = 2\n");
    bool read_b = false;
    const auto r = read_table(
        t, {"t.toml", "x"},
        {{"a", Type::integer, [](const Entry& e) -> Expected<void> { return e.fail("no"); }},
         {"b", Type::integer, [&](const Entry&) -> Expected<void> {
              read_b = true;
              return {};
          }}});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:1:5: x.a: no");
    EXPECT_FALSE(read_b);
}

TEST(ConfigSchema, NestedTableContinuesThePath) {
    const auto t = parse("[inject.fals]\nnumber = 3\ncolour = 1\n");
    std::uint16_t number = 0;
    const auto r =
        read_table(t, {"t.toml", "", At::key},
                   {{"inject", Type::table, [&](const Entry& e) {
                         return read_table(e, {{"fals", Type::table, [&](const Entry& f) {
                                                    return read_table(
                                                        f, {integer_key("number", number, 1, 511)});
                                                }}});
                     }}});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:3:1: inject.fals.colour: unknown key");
    EXPECT_EQ(number, 3);
}

TEST(ConfigSchema, CustomUnknownComplaint) {
    const auto t = parse("frequency = 1\n");
    const auto r = read_table(
        t, {"t.toml", "signal[0]", At::value, "", "unknown key for kind = \"sine\""}, {});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:1:1: signal[0].frequency: unknown key for kind = \"sine\"");
}

TEST(ConfigSchema, BridgeWordingNamesTheTable) {
    const auto t = parse("[mqtt]\nport = \"x\"\n");
    const auto& mqtt = *t["mqtt"].as_table();
    const Table how{"t.toml", "", At::value, "[mqtt]"};
    std::uint16_t port = 0;
    const auto typed = read_table(mqtt, how, {integer_key("port", port, 1, 65535)});
    ASSERT_FALSE(typed);
    EXPECT_EQ(typed.error(), "t.toml:2:8: port must be an integer");
    const auto unknown = read_table(mqtt, how, {{"host", Type::string, {}}});
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.error(), "t.toml:2:1: unknown key 'port' in [mqtt]");
    const auto missing =
        read_table(mqtt, how, {{"port", Type::any, {}}, {"host", Type::string, {}, true}});
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error(), "t.toml:1:1: [mqtt] needs 'host'");
}

TEST(ConfigSchema, PositionAndFailAt) {
    const auto t = parse("\n  a = 1\n");
    const auto& where = t["a"].node()->source();
    EXPECT_EQ(position("f.toml", where), "f.toml:2:7");
    EXPECT_EQ(fail_at("f.toml", where, "a", "bad").value(), "f.toml:2:7: a: bad");
    EXPECT_EQ(fail_at("f.toml", where, "", "bad").value(), "f.toml:2:7: bad");
}

}  // namespace
}  // namespace fins::config
