// A repeated [[plc]] (`repeat = { networks = ..., nodes = ... }`, config_plant.cpp;
// docs/networks.md "A plant of 10,000 CPU Units"): one CPU Unit per network and node,
// placeholders in its strings, the repeated network on its units, and errors that name
// the position, the key and the CPU Unit.
#include <gtest/gtest.h>

#include "finsd/config.hpp"
#include "finsd/config_plant.hpp"
#include "server/routing/plant.hpp"

namespace fins::finsd {
namespace {

Expected<Settings> load(std::string_view text) {
    Settings s;
    if (auto r = load_config_text(text, "site.toml", s); !r) return tl::unexpected(r.error());
    return s;
}

TEST(FinsdPlantRepeat, OneCpuUnitPerNetworkAndNodeWithPlaceholdersReplaced) {
    const auto s = load(R"(
[[plc]]
name = "router"
  [[plc.ethernet]]
  network = 1
  bind = "127.0.1.1"
[[plc]]
name = "cell-{network}-{node}"
profile = "cj2h"
mode = "monitor"
data_dir = "/var/lib/finsd/{index}"
repeat = { networks = "20-22", nodes = "1-4" }
  [[plc.ethernet]]
  bind = "127.0.{network}.{node}"
  tcp = false
  [[plc.ethernet]]
  unit = 1
  network = 100
  node = 9
  bind = "127.0.100.9"
  address_method = "table"
  [plc.memory]
  D0 = 7
)");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->plant.cpus.size(), 1u + 3u * 4u);
    ASSERT_EQ(s->plant_cpu.size(), s->plant.cpus.size());
    // Networks outer, nodes inner; {index} counts from 0 in that order.
    const auto& c = s->plant.cpus[1 + 4 + 2];  // network 21, node 3
    EXPECT_EQ(c.name, "cell-21-3");
    EXPECT_EQ(c.profile, "cj2h");
    EXPECT_EQ(c.mode, plc::OperatingMode::monitor);
    ASSERT_TRUE(c.data_dir);
    EXPECT_EQ(c.data_dir->string(), "/var/lib/finsd/6");
    ASSERT_EQ(c.ports.size(), 2u);
    EXPECT_EQ(c.ports[0].network, 21);  // the repeated network: it gave none
    EXPECT_EQ(c.ports[0].bind, "127.0.21.3");
    EXPECT_FALSE(c.ports[0].tcp);
    EXPECT_EQ(c.ports[1].network, 100);  // its own
    EXPECT_EQ(s->plant_cpu[7].memory.size(), 1u);
    EXPECT_EQ(s->plant.cpus.back().name, "cell-22-4");
    EXPECT_EQ(s->plant.cpus.back().ports[0].bind, "127.0.22.4");
    // Every unit on network 100 is node 9 of it: the plant's cross-check says so.
    EXPECT_NE(server::validate_plant(s->plant).find("node 100.9 exists twice"), std::string::npos)
        << server::validate_plant(s->plant);
}

TEST(FinsdPlantRepeat, ASingleNetworkOrNodeIsAnInteger) {
    const auto s = load(
        "[[plc]]\nname = \"line-{node}\"\nrepeat = { networks = 3, nodes = \"10 - 12\" }\n"
        "[[plc.ethernet]]\nbind = \"10.0.3.{node}\"\n");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->plant.cpus.size(), 3u);
    EXPECT_EQ(s->plant.cpus[2].name, "line-12");
    EXPECT_EQ(s->plant.cpus[2].ports[0].network, 3);
    EXPECT_EQ(server::validate_plant(s->plant), "");
}

TEST(FinsdPlantRepeat, ErrorsNameThePositionTheKeyAndTheCpuUnit) {
    const auto error = [](std::string_view repeat, std::string_view name = "c-{index}",
                          std::string_view bind = "127.0.{network}.{node}") {
        const auto s =
            load("[[plc]]\nname = \"" + std::string(name) + "\"\nrepeat = " + std::string(repeat) +
                 "\n[[plc.ethernet]]\nbind = \"" + std::string(bind) + "\"\n");
        return s ? std::string("loaded") : s.error();
    };
    EXPECT_EQ(error("3"),
              "site.toml:3:10: plc[0].repeat: must be a table: { networks = \"20-59\", nodes = "
              "\"1-250\" }");
    EXPECT_EQ(error("{ nodes = \"1-3\" }"),
              "site.toml:3:10: plc[0].repeat: needs networks and nodes");
    EXPECT_EQ(error("{ networks = 1, nodes = \"1-3\", step = 2 }"),
              "site.toml:3:41: plc[0].repeat.step: unknown key");
    EXPECT_EQ(error("{ networks = 128, nodes = 1 }"),
              "site.toml:3:23: plc[0].repeat.networks: 128 is not 1-127");
    EXPECT_EQ(error("{ networks = 1, nodes = \"0-3\" }"),
              "site.toml:3:34: plc[0].repeat.nodes: 0-3 is not a range within 1-254");
    EXPECT_EQ(error("{ networks = 1, nodes = \"9-3\" }"),
              "site.toml:3:34: plc[0].repeat.nodes: 9-3 is not a range within 1-254");
    EXPECT_EQ(error("{ networks = 1, nodes = \"1..3\" }"),
              "site.toml:3:34: plc[0].repeat.nodes: must be an integer or a range "
              "\"FIRST-LAST\"");
    // Names that would repeat.
    EXPECT_EQ(error("{ networks = \"1-2\", nodes = \"1-3\" }", "cell-{node}"),
              "site.toml:2:8: plc[0].name: with repeat, must contain {index}, or {node} (and "
              "{network} when several networks repeat)");
    EXPECT_EQ(error("{ networks = 1, nodes = \"1-3\" }", "cell"),
              "site.toml:2:8: plc[0].name: with repeat, must contain {index}, or {node} (and "
              "{network} when several networks repeat)");
    EXPECT_EQ(error("{ networks = 1, nodes = \"1-3\" }", "cell-{node}"), "loaded");
    // A unit's own error names which CPU Unit of the repeat it is.
    EXPECT_EQ(error("{ networks = 1, nodes = \"254-254\" }", "c-{node}", "127.0.{network}.{node}0"),
              "site.toml:5:8: plc[0](1.254).ethernet[0].bind: '127.0.1.2540' is not an IPv4 "
              "address");
}

TEST(FinsdPlantRepeat, TwoCpuUnitsOnOneDataDirAreRefused) {
    const auto s = load(
        "[[plc]]\nname = \"c-{node}\"\ndata_dir = \"/tmp/site\"\nrepeat = { networks = 1, nodes "
        "= \"1-2\" }\n[[plc.ethernet]]\nbind = \"127.0.1.{node}\"\n");
    ASSERT_TRUE(s) << s.error();
    EXPECT_EQ(server::validate_plant(s->plant),
              "plc \"c-2\": data_dir /tmp/site is plc \"c-1\"'s too");
}

}  // namespace
}  // namespace fins::finsd
