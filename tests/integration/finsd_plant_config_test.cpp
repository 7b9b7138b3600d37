// The [[plc]] configuration (cli/finsd/config_plant.hpp; README "A plant of several
// networks"): parsed keys, positioned errors, and the plant's cross-field checks.
#include <gtest/gtest.h>

#include "cli/finsd/config.hpp"
#include "server/routing/plant.hpp"

namespace fins::cli::finsd {
namespace {

Expected<Settings> load(std::string_view text) {
    Settings s;
    if (auto r = load_config_text(text, "plant.toml", s); !r) return tl::unexpected(r.error());
    return s;
}

TEST(FinsdPlantConfig, ParsesCpuUnitsUnitsIpTablesAndRelays) {
    const auto s = load(R"(
[[plc]]
name = "router"
profile = "cs1h"
mode = "monitor"
gateway_count = 7
  [[plc.ethernet]]
  unit = 0
  network = 1
  bind = "127.0.1.1"
  [[plc.ethernet]]
  unit = 3
  network = 2
  node = 40
  bind = "127.0.2.9"
  port = 9700
  tcp = false
  max_connections = 4
  address_method = "combined"
  dynamic_remote_ip = false
    [[plc.ethernet.ip_table]]
    node = 7
    ip = "127.0.2.77"
  [[plc.relay]]
  network = 5
  via_network = 2
  via_node = 8
)");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->plant.cpus.size(), 1u);
    const auto& cpu = s->plant.cpus[0];
    EXPECT_EQ(cpu.name, "router");
    EXPECT_EQ(cpu.profile, "cs1h");
    EXPECT_EQ(cpu.mode, plc::OperatingMode::monitor);
    EXPECT_EQ(cpu.gateway_count, 7);
    ASSERT_EQ(cpu.ports.size(), 2u);
    const auto& p = cpu.ports[1];
    EXPECT_EQ(p.unit_number, 3);
    EXPECT_EQ(p.network, 2);
    EXPECT_EQ(p.node, 40);
    EXPECT_EQ(p.port, 9700);
    EXPECT_FALSE(p.tcp);
    EXPECT_EQ(p.max_connections, 4u);
    EXPECT_EQ(p.method, server::AddressMethod::combined);
    EXPECT_FALSE(p.dynamic_remote_ip);
    ASSERT_EQ(p.ip_table.size(), 1u);
    EXPECT_EQ(p.ip_table[0].node, 7);
    EXPECT_EQ(p.ip_table[0].ip, (std::array<std::uint8_t, 4>{127, 0, 2, 77}));
    ASSERT_EQ(cpu.relays.size(), 1u);
    EXPECT_EQ(cpu.relays[0], (plc::RelayNetwork{5, 2, 8}));
    EXPECT_EQ(server::validate_plant(s->plant), "");
}

TEST(FinsdPlantConfig, ErrorsNameTheFilePositionAndKey) {
    const auto bad_method = load(
        "[[plc]]\nname = \"a\"\n[[plc.ethernet]]\nbind = \"127.0.1.1\"\naddress_method = "
        "\"dhcp\"\n");
    ASSERT_FALSE(bad_method);
    EXPECT_EQ(bad_method.error(),
              "plant.toml:5:18: plc[0].ethernet[0].address_method: 'dhcp' is not automatic, "
              "automatic-static, table or combined");
    const auto unknown = load("[[plc]]\nname = \"a\"\ncolour = 1\n");
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.error(), "plant.toml:3:1: plc[0].colour: unknown key");
    const auto network = load("[[plc]]\nname = \"a\"\n[[plc.ethernet]]\nnetwork = 128\n");
    ASSERT_FALSE(network);
    EXPECT_EQ(network.error(), "plant.toml:4:11: plc[0].ethernet[0].network: 128 is not 1-127");
    EXPECT_FALSE(load("[[plc]]\nprofile = \"cj2h\"\n"));  // no name
}

TEST(FinsdPlantConfig, EachCpuUnitTakesAMemoryTableOfItsOwn) {
    const auto s = load(R"(
[[plc]]
name = "a"
  [plc.memory]
  "D100" = 1
  "W0.03" = true
  "D200" = { float = 1.5 }
[[plc]]
name = "b"
memory = { "D100" = [2, 3] }
)");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->plant_cpu.size(), 2u);
    ASSERT_EQ(s->plant_cpu[0].memory.size(), 3u);  // in file order
    EXPECT_EQ(s->plant_cpu[0].memory[0].key, "D100");
    EXPECT_EQ(s->plant_cpu[0].memory[0].values, std::vector<std::uint32_t>{1});
    EXPECT_EQ(s->plant_cpu[0].memory[1].values, std::vector<std::uint32_t>{1});
    EXPECT_EQ(s->plant_cpu[0].memory[2].values, (std::vector<std::uint32_t>{0x0000, 0x3FC0}));
    EXPECT_EQ(s->plant_cpu[0].memory[0].path, "plc[0].memory.\"D100\"");
    EXPECT_EQ(s->plant_cpu[1].memory[0].values, (std::vector<std::uint32_t>{2, 3}));
    EXPECT_TRUE(s->memory.empty());  // the top-level [memory] is another thing

    const auto bad = load("[[plc]]\nname = \"a\"\n[plc.memory]\n\"Q5\" = 1\n");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(),
              "plant.toml:4:1: plc[0].memory.\"Q5\": not a PLC address (e.g. D100, H0, "
              "CIO10.13, E3_100)");
    const auto not_table = load("[[plc]]\nname = \"a\"\nmemory = 5\n");
    ASSERT_FALSE(not_table);
    EXPECT_EQ(not_table.error(),
              "plant.toml:3:10: plc[0].memory: must be a table of ADDRESS = value(s)");
}

TEST(FinsdPlantConfig, EachCpuUnitTakesProtectionAndInjectionsOfItsOwn) {
    const auto s = load(R"(
[[plc]]
name = "guarded"
  [plc.protection]
  network_write = "listed"
  nodes = ["1.5"]
  um_read = true
  password = "secret"
  [plc.inject]
  battery_error = true
  fal = [{ number = 12, message = "low level" }]
[[plc]]
name = "open"
)");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->plant_cpu.size(), 2u);
    const auto& guarded = s->plant_cpu[0];
    EXPECT_EQ(guarded.network_write_protection.mode, plc::NetworkWriteProtection::listed);
    ASSERT_EQ(guarded.network_write_protection.nodes.size(), 1u);
    EXPECT_TRUE(guarded.um_read_protection);
    EXPECT_EQ(guarded.um_password, "secret");
    EXPECT_TRUE(guarded.inject.battery_error);
    ASSERT_EQ(guarded.inject.fal.size(), 1u);
    EXPECT_EQ(guarded.inject.fal[0].number, 12);
    const auto& open = s->plant_cpu[1];
    EXPECT_EQ(open.network_write_protection.mode, plc::NetworkWriteProtection::off);
    EXPECT_FALSE(open.inject.battery_error);
    // The top-level tables are the single node's, untouched.
    EXPECT_FALSE(s->um_read_protection);
    EXPECT_FALSE(s->inject.battery_error);

    const auto bad_mode = load("[[plc]]\nname = \"a\"\n[plc.protection]\nnetwork_write = \"x\"\n");
    ASSERT_FALSE(bad_mode);
    EXPECT_EQ(bad_mode.error(),
              "plant.toml:4:1: plc[0].protection.network_write: 'x' is not off, "
              "all, listed or all-except-listed");
    const auto bad_fal = load("[[plc]]\nname = \"a\"\n[plc.inject]\nfal = [{ number = 600 }]\n");
    ASSERT_FALSE(bad_fal);
    EXPECT_NE(bad_fal.error().find("plc[0].inject.fal[0].number: 600 is not 1-511"),
              std::string::npos)
        << bad_fal.error();
    const auto listed_nothing =
        load("[[plc]]\nname = \"a\"\n[plc.protection]\nnetwork_write = \"listed\"\n");
    ASSERT_FALSE(listed_nothing);
    EXPECT_NE(listed_nothing.error().find("protects nothing"), std::string::npos)
        << listed_nothing.error();
}

TEST(FinsdPlantConfig, W420_5_2_AutomaticGenerationNeedsNodeEqualToTheLastOctet) {
    auto s = load("[[plc]]\nname = \"a\"\n[[plc.ethernet]]\nbind = \"127.0.1.5\"\nnode = 6\n");
    ASSERT_TRUE(s) << s.error();
    EXPECT_NE(server::validate_plant(s->plant).find("differs from the last octet"),
              std::string::npos);
    s->plant.cpus[0].ports[0].method = server::AddressMethod::table;
    EXPECT_EQ(server::validate_plant(s->plant), "");
}

TEST(FinsdPlantConfig, CrossChecksRefuseDuplicatesAndForeignRelayNetworks) {
    server::PlantConfig c;
    server::PlantCpuConfig a;
    a.name = "a";
    server::PlantPortConfig p;
    p.bind = "127.0.1.1";
    a.ports = {p};
    c.cpus = {a, a};
    EXPECT_NE(server::validate_plant(c).find("used twice"), std::string::npos);
    c.cpus[1].name = "b";
    EXPECT_NE(server::validate_plant(c).find("exists twice in the plant"), std::string::npos);
    c.cpus.pop_back();
    c.cpus[0].relays = {{3, 2, 2}};
    EXPECT_NE(server::validate_plant(c).find("relay network 2 is not"), std::string::npos);
    c.cpus[0].relays = {{1, 1, 2}};
    EXPECT_NE(server::validate_plant(c).find("a local network"), std::string::npos);
}

}  // namespace
}  // namespace fins::cli::finsd
