// The [[plc]] configuration (finsd/config_plant.hpp; README "A plant of several
// networks"): parsed keys, positioned errors, and the plant's cross-field checks.
#include <gtest/gtest.h>

#include "finsd/config.hpp"
#include "finsd/config_plant.hpp"
#include "server/routing/plant.hpp"

namespace fins::finsd {
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

// [plc.storage], [plc.serial], [[plc.remote]] and [[plc.schedule]] are read by the single
// node's loaders ([storage], [serial], [[remote]], [[schedule]]) for that CPU Unit only.
TEST(FinsdPlantConfig, EachCpuUnitTakesStorageSerialRemotesAndScheduleOfItsOwn) {
    const auto s = load(R"(
[[plc]]
name = "a"
data_dir = "/tmp/a"
  [plc.storage]
  durability = "power"
  [plc.serial]
  cpu = "/dev/ttyUSB0,baud=19200"
  "scu1.2" = "/dev/ttyUSB1,timeout=2.5"
  [[plc.remote]]
  node = 9
  address = "127.0.0.9:9700"
  [[plc.schedule]]
  every = "250ms"
  instruction = "send"
  dest = "1.9.0"
  local = "D100"
  remote = "D200"
  count = 2
  [[plc.ethernet]]
  bind = "127.0.1.1"
[[plc]]
name = "b"
  [[plc.ethernet]]
  bind = "127.0.1.2"
)");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->plant_cpu.size(), 2u);
    const auto& a = s->plant.cpus[0];
    const auto& b = s->plant.cpus[1];
    EXPECT_EQ(a.durability, plc::Durability::power);
    EXPECT_EQ(b.durability, plc::Durability::process);
    ASSERT_EQ(s->plant_cpu[0].serial.size(), 2u);
    EXPECT_EQ(s->plant_cpu[0].serial[0].name, "cpu");
    EXPECT_EQ(s->plant_cpu[0].serial[0].mode, "hostlink");
    EXPECT_EQ(s->plant_cpu[0].serial[1].name, "scu1.2");
    EXPECT_EQ(s->plant_cpu[0].serial[1].mode, "gateway");
    ASSERT_EQ(a.remotes.size(), 1u);
    EXPECT_EQ(a.remotes[0].node, 9);
    EXPECT_EQ(a.remotes[0].port, 9700);
    ASSERT_EQ(s->plant_cpu[0].schedule.size(), 1u);
    EXPECT_EQ(s->plant_cpu[0].schedule[0].scheduled.every, std::chrono::milliseconds(250));
    EXPECT_EQ(s->plant_cpu[0].schedule[0].scheduled.request.count, 2);
    EXPECT_TRUE(s->plant_cpu[1].serial.empty());
    EXPECT_TRUE(b.remotes.empty());
    EXPECT_TRUE(s->plant_cpu[1].schedule.empty());
    // The top-level tables are the single node's, untouched.
    EXPECT_EQ(s->durability, plc::Durability::process);
    EXPECT_TRUE(s->serial.empty());
    EXPECT_TRUE(s->remotes.empty());
    EXPECT_TRUE(s->schedule.empty());
    EXPECT_EQ(server::validate_plant(s->plant), "");
}

TEST(FinsdPlantConfig, StorageSerialRemoteAndScheduleErrorsNamePlcN) {
    const std::string b = "[[plc]]\nname = \"a\"\n[[plc]]\nname = \"b\"\n";
    const auto power = load(b + "[plc.storage]\ndurability = \"power\"\n");
    ASSERT_FALSE(power);
    EXPECT_EQ(power.error(),
              "plant.toml:5:1: plc[1].storage.durability: \"power\" needs data_dir (without one "
              "nothing is kept)");
    const auto storage = load(b + "[plc.storage]\ndurability = \"disk\"\n");
    ASSERT_FALSE(storage);
    EXPECT_EQ(storage.error(),
              "plant.toml:6:1: plc[1].storage.durability: 'disk' is not process or power");
    const auto serial = load(b + "[plc.serial]\ncpu = \"/dev/x,baud=12345\"\n");
    ASSERT_FALSE(serial);
    EXPECT_EQ(serial.error().rfind("plant.toml:6:1: plc[1].serial.cpu: baud '12345'", 0), 0u)
        << serial.error();
    const auto cpu_gateway = load(b + "[plc.serial]\ncpu = \"/dev/x,mode=gateway\"\n");
    ASSERT_FALSE(cpu_gateway);
    EXPECT_EQ(cpu_gateway.error().rfind("plant.toml:6:1: plc[1]: serial port cpu: mode", 0), 0u)
        << cpu_gateway.error();
    const auto remote = load(b + "[[plc.remote]]\nnode = 5\n");
    ASSERT_FALSE(remote);
    EXPECT_EQ(remote.error(), "plant.toml:5:1: plc[1].remote[0]: needs node and address");
    const auto schedule = load(b + "[[plc.schedule]]\nevery = \"1ms\"\n");
    ASSERT_FALSE(schedule);
    EXPECT_EQ(schedule.error().rfind("plant.toml:6:9: plc[1].schedule[0].every: must be", 0), 0u)
        << schedule.error();
    // A Serial Communications Unit cannot take the unit number of an Ethernet unit, nor a
    // gateway port lead to a network one of the CPU Unit's Ethernet units is on.
    const std::string unit1 = "[[plc.ethernet]]\nunit = 1\nnetwork = 4\nbind = \"127.0.1.1\"\n";
    const auto clash = load(b + unit1 + "[plc.serial]\n\"scu1.1\" = \"/dev/x\"\n");
    ASSERT_FALSE(clash);
    EXPECT_EQ(clash.error(),
              "plant.toml:10:1: plc[1].serial.scu1.1: unit number 1 is the [[plc.ethernet]] "
              "unit's");
    const auto network = load(b + unit1 + "[plc.serial]\n\"scu2.1\" = \"/dev/x,network=4\"\n");
    ASSERT_FALSE(network);
    EXPECT_EQ(network.error(),
              "plant.toml:10:1: plc[1].serial.scu2.1: network=4 is the network of "
              "[[plc.ethernet]] unit 1");
}

// [plc.files] is the single node's [files] for one CPU Unit: the same keys, read by the
// same loader, checked against that CPU Unit's model; errors name plc[N].files.
TEST(FinsdPlantConfig, EachCpuUnitTakesAFilesTableOfItsOwn) {
    const auto s = load(R"(
[[plc]]
name = "a"
profile = "cp1h"
  [plc.files]
  cassette = false
[[plc]]
name = "b"
  [plc.files]
  card_kbytes = 2048
  em_file_bank = 20
[[plc]]
name = "c"
  [plc.files]
  card = false
)");
    ASSERT_TRUE(s) << s.error();
    ASSERT_EQ(s->plant.cpus.size(), 3u);
    const auto& a = s->plant.cpus[0].files;
    EXPECT_EQ(a.cassette, false);
    EXPECT_FALSE(a.card_kbytes || a.em_file_bank);  // the CP1H's
    const auto& b = s->plant.cpus[1].files;
    EXPECT_EQ(b.card_kbytes, 2048u);
    EXPECT_EQ(b.em_file_bank, 20);
    EXPECT_FALSE(b.cassette);
    EXPECT_EQ(s->plant.cpus[2].files.card_kbytes, 0u);               // no card
    EXPECT_FALSE(s->card_kbytes || s->em_file_bank || s->cassette);  // not the single node's
}

TEST(FinsdPlantConfig, FilesErrorsNamePlcN) {
    const std::string b = "[[plc]]\nname = \"a\"\n[[plc]]\nname = \"b\"\n";
    const auto range = load(b + "[plc.files]\nem_file_bank = 25\n");
    ASSERT_FALSE(range);
    EXPECT_EQ(range.error(), "plant.toml:6:1: plc[1].files.em_file_bank: 25 is not 0-24");
    const auto unknown = load(b + "[plc.files]\nslots = 2\n");
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.error(), "plant.toml:6:1: plc[1].files.slots: unknown key");
    // The model's devices: the CJ2H has no cassette slot, the CJ1M no EM bank.
    const auto cassette = load(b + "[plc.files]\ncassette = true\n");
    ASSERT_FALSE(cassette);
    EXPECT_EQ(cassette.error(),
              "plant.toml:5:1: plc[1].files.cassette: the cj2h has no Memory Cassette slot (22 "
              "20 is a CP1H command)");
    const auto bank = load(b + "profile = \"cj1m\"\n[plc.files]\nem_file_bank = 0\n");
    ASSERT_FALSE(bank);
    EXPECT_EQ(bank.error(), "plant.toml:6:1: plc[1].files.em_file_bank: the cj1m has no EM bank 0");
}

// One translation of an Ethernet unit's settings into server options, for the single node
// (its [network] keys) and each unit of a plant.
TEST(FinsdPlantConfig, SingleNodeAndPlantUnitsShareOneServerOptionsTranslation) {
    auto s = load(R"(
[network]
bind = "127.0.7.3"
port = 9777
node = 33
network = 7
udp = false
max_connections = 5
tcp_frame_timeout = 3
tcp_keepalive = 0
tcp_max_pending = 4
)");
    ASSERT_TRUE(s) << s.error();
    const auto o = server::options_for(single_unit(*s), tcp_limits(*s));
    EXPECT_EQ(o.bind_address, "127.0.7.3");
    EXPECT_EQ(o.port, 9777);
    EXPECT_EQ(o.node, 33);
    EXPECT_EQ(o.network, 7);
    EXPECT_FALSE(o.udp);
    EXPECT_TRUE(o.tcp);
    EXPECT_EQ(o.max_tcp_connections, 5u);
    EXPECT_EQ(o.tcp_limits.frame_timeout, std::chrono::seconds(3));
    EXPECT_EQ(o.tcp_limits.handshake_timeout, std::chrono::seconds(10));
    EXPECT_EQ(o.tcp_limits.keepalive, std::chrono::seconds(0));
    EXPECT_EQ(o.tcp_limits.max_pending, 4u);
    EXPECT_EQ(o.router, nullptr);
}

}  // namespace
}  // namespace fins::finsd
