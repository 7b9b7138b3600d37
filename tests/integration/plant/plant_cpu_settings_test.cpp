// Each [[plc]] of a plant takes a memory table, protections and injections of its own
// (README "A plant of several networks"): finsd applies them to that CPU Unit at start,
// and refuses a memory entry the CPU Unit's model cannot hold (exit 2, naming it).
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fins/address.hpp"
#include "integration/support/finsd_process.hpp"
#include "integration/support/plant_fixture.hpp"

namespace fins::test {
namespace {

// Two CPU Units, one Ethernet unit each, on loopback addresses no other test binds;
// `b_extra` and `a_extra` are more keys and tables of each.
std::string plant(const std::string& b_extra, const std::string& a_extra = "") {
    return R"(
[[plc]]
name = "line-a"
)" + a_extra +
           R"(
  [plc.memory]
  "D100" = [11, 12]
  "W3.04" = true
  [[plc.ethernet]]
  network = 1
  bind = "127.0.61.1"
  port = 9611
[[plc]]
name = "line-b"
profile = "cj1m"
)" + b_extra +
           R"(
  [[plc.ethernet]]
  network = 2
  bind = "127.0.62.1"
  port = 9611
)";
}

std::unique_ptr<Client> client_of(const std::string& host) {
    ClientOptions o;
    o.host = host;
    o.port = 9611;
    o.timeout = std::chrono::milliseconds(3000);
    auto c = Client::connect(o);
    EXPECT_TRUE(c) << c.error().message();
    return c ? std::move(*c) : nullptr;
}

std::vector<std::uint16_t> words_at(const std::string& host, const std::string& address,
                                    std::uint16_t count) {
    auto c = client_of(host);
    if (!c) return {};
    auto got = c->read_words(*parse_address(address), count);
    EXPECT_TRUE(got) << got.error().message();
    return got ? *got : std::vector<std::uint16_t>{};
}

TEST(PlantCpuSettings, EachCpuUnitStartsWithItsOwnMemoryTable) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-memory");
    Finsd d(
        {"--config",
         dir.write("plant.toml", plant("memory = { \"D100\" = 21, \"D101\" = { int16 = -2 } }"))});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_EQ(words_at("127.0.61.1", "D100", 2), (std::vector<std::uint16_t>{11, 12}));
    EXPECT_EQ(words_at("127.0.61.1", "W3", 1), std::vector<std::uint16_t>{0x0010});
    EXPECT_EQ(words_at("127.0.62.1", "D100", 2), (std::vector<std::uint16_t>{21, 0xFFFE}));
    EXPECT_EQ(words_at("127.0.62.1", "W3", 1), std::vector<std::uint16_t>{0});
}

TEST(PlantCpuSettings, EntryTheCpuUnitCannotHoldIsRefusedWithItsName) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-memory");
    // The CJ1M has no EM area: the entry is refused for line-b, naming it and the model.
    const auto file = dir.write("plant.toml", plant("memory = { \"E0_0\" = 1 }"));
    Finsd d({"--config", file});
    ASSERT_FALSE(d.started());
    EXPECT_EQ(d.result().exit_code, 2) << d.result().err;
    EXPECT_NE(d.result().err.find("plc[1].memory.\"E0_0\": "), std::string::npos) << d.result().err;
}

TEST(PlantCpuSettings, EachCpuUnitHasItsOwnProtectionAndInjections) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-settings");
    // line-a: network write protection for every node; line-b: a battery error.
    const auto config = plant("  [plc.inject]\n  battery_error = true\n",
                              "  [plc.protection]\n  network_write = \"all\"\n");
    Finsd d({"--config", dir.write("plant.toml", config)});
    ASSERT_TRUE(d.started()) << d.result().err;
    const std::vector<std::uint8_t> write_d0{0x82, 0, 0, 0, 0, 1, 0x12, 0x34};
    auto a = client_of("127.0.61.1");
    ASSERT_NE(a, nullptr);
    EXPECT_EQ(end_code(*a, CommandCode{0x01, 0x02}, write_d0), 0x2102u);  // W342 5-1-2
    auto b = client_of("127.0.62.1");
    ASSERT_NE(b, nullptr);
    // Written, with the battery error's flag on the answer (end code bit 6, W342 5-1-3);
    // line-a has no error to flag.
    const auto written = b->send_raw(CommandCode{0x01, 0x02}, write_d0);
    ASSERT_TRUE(written) << written.error().message();
    EXPECT_EQ(static_cast<unsigned>(written->code.end_code()), 0x0000u);
    EXPECT_TRUE(written->code.non_fatal_cpu_error());
    const std::vector<std::uint8_t> read_d0{0x82, 0, 0, 0, 0, 1};
    const auto read = a->send_raw(CommandCode{0x01, 0x01}, read_d0);
    ASSERT_TRUE(read) << read.error().message();
    EXPECT_FALSE(read->code.non_fatal_cpu_error());
}

// Newcomer 12: in a plant, --port (and [network] port) is the port of every
// [[plc.ethernet]] unit that sets none of its own (default 9600); a unit's `port` wins.
// finsd_run.hpp passes --port 0: line-a listens on a free port, line-b on its 9611.
TEST(PlantCpuSettings, PortFlagIsThePortOfUnitsWithoutOneOfTheirOwn) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-port");
    auto config = plant("");
    const std::string fixed = "  bind = \"127.0.61.1\"\n  port = 9611\n";
    config.replace(config.find(fixed), fixed.size(), "  bind = \"127.0.61.1\"\n");
    Finsd d({"--config", dir.write("plant.toml", config)});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_NE(d.port(), 9600);  // "listening": the first unit's port
    ClientOptions o;
    o.host = "127.0.61.1";
    o.port = d.port();
    o.timeout = std::chrono::milliseconds(3000);
    auto a = Client::connect(o);
    ASSERT_TRUE(a) << a.error().message();
    EXPECT_EQ(words_of(**a, "D100", 2), (std::vector<std::uint16_t>{11, 12}));
    EXPECT_EQ(words_at("127.0.62.1", "D100", 2), (std::vector<std::uint16_t>{0, 0}));
}

// [plc.storage] durability: "power" fdatasyncs that CPU Unit's state file before each
// write's answer ([storage] durability of a single node); the other CPU Unit never syncs.
TEST(PlantCpuSettings, EachCpuUnitHasItsOwnDurability) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-durability");
    server::PlantConfig config;
    for (const char* name : {"a", "b"}) {
        server::PlantCpuConfig cpu;
        cpu.name = name;
        cpu.data_dir = dir.path() / name;
        cpu.ports = {plant_port(0, 1, name[0] == 'a' ? "127.0.67.1" : "127.0.67.2")};
        config.cpus.push_back(cpu);
    }
    config.cpus[0].durability = plc::Durability::power;
    PlantThread plant(config);
    for (const auto& [cpu, host] : {std::pair{0, "127.0.67.1"}, std::pair{1, "127.0.67.2"}}) {
        auto c = plant.client(host, plant.port(static_cast<std::size_t>(cpu)),
                              {1, static_cast<std::uint8_t>(cpu + 1), 0});
        ASSERT_NE(c, nullptr);
        ASSERT_TRUE(c->write_words(*parse_address("D0"), std::vector<std::uint16_t>{1}));
    }
    EXPECT_EQ(plant.plant().plc(0).storage().syncs(), 1u);
    EXPECT_EQ(plant.plant().plc(1).storage().syncs(), 0u);
}

// The single node's [storage], [serial], [[remote]] and [[schedule]] describe no CPU Unit
// of a plant: finsd says they are ignored and where a plant takes them.
TEST(PlantCpuSettings, SingleNodeTablesInAPlantAreNamedAsIgnored) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-ignored");
    const std::string single = R"(
[[remote]]
node = 9
address = "127.0.0.9"
[[schedule]]
every = "1s"
instruction = "sendcmd"
dest = "0.9.0"
command = "0501"
)";
    Finsd d({"--config", dir.write("plant.toml", single + plant(""))});
    ASSERT_TRUE(d.started()) << d.result().err;
    const auto err = d.stop().err;
    EXPECT_NE(err.find("[[remote]] (a [[plc]] takes its own [[plc.remote]])"), std::string::npos)
        << err;
    EXPECT_NE(err.find("[[schedule]] (a [[plc]] takes its own [[plc.schedule]])"),
              std::string::npos)
        << err;
}

}  // namespace
}  // namespace fins::test
