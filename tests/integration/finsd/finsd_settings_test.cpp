// finsd's settings without a process: the TOML loader, flag overrides, validation and
// the [memory] initial values (src/finsd/config.hpp, linked from fins_finsd).
#include "finsd/config.hpp"

#include <gtest/gtest.h>

namespace fins::finsd {
namespace {

using plc::NetworkWriteProtection;

Settings load(std::string_view text) {
    Settings s;
    auto r = load_config_text(text, "t.toml", s);
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error());
    return s;
}

std::string error_of(std::string_view text) {
    Settings s;
    auto r = load_config_text(text, "t.toml", s);
    return r ? std::string("loaded") : r.error();
}

TEST(FinsdSettings, EmptyFileKeepsTheDefaults) {
    const Settings s = load("");
    EXPECT_EQ(s.profile, "cj2h");
    EXPECT_EQ(s.mode, plc::OperatingMode::run);
    EXPECT_EQ(s.bind, "127.0.0.1");
    EXPECT_EQ(s.port, 9600);
    EXPECT_EQ(s.node, 0);
    EXPECT_TRUE(s.udp && s.tcp);
    EXPECT_EQ(s.max_connections, 16u);
    EXPECT_FALSE(s.data_dir || s.control_socket);
    EXPECT_EQ(s.network_write_protection.mode, NetworkWriteProtection::off);
    EXPECT_TRUE(validate(s).has_value());
}

TEST(FinsdSettings, EveryKeyIsRead) {
    const Settings s = load(R"(
profile = "NX102-9000"
mode = "monitor"
data_dir = "/tmp/d"
control = "/tmp/c.sock"
log_level = "warn"
[network]
bind = "::1"
port = 9601
node = 7
network = 3
udp = false
tcp = true
max_connections = 4
[protection]
network_write = "all-except-listed"
nodes = ["1.20", "2.*"]
um_read = true
dip_write = true
[memory]
"D100" = [1, 2, 3]
"CIO10.13" = true
"W0.0" = [true, 0, 1]
"IR0" = 0x12345678
[inject]
battery_error = true
fal = [{ number = 5, message = "JAM" }, { number = 6 }]
fals = { number = 9, message = "STOP" }
messages = { 0 = "hello", 7 = "bye" }
errors = [0x0203]
)");
    EXPECT_EQ(s.profile, "NX102-9000");
    EXPECT_EQ(s.mode, plc::OperatingMode::monitor);
    EXPECT_EQ(s.data_dir->string(), "/tmp/d");
    EXPECT_EQ(s.control_socket->string(), "/tmp/c.sock");
    EXPECT_EQ(s.log_level, "warn");
    EXPECT_EQ(s.bind, "::1");
    EXPECT_EQ(s.port, 9601);
    EXPECT_EQ(s.node, 7);
    EXPECT_EQ(s.network, 3);
    EXPECT_FALSE(s.udp);
    EXPECT_TRUE(s.tcp);
    EXPECT_EQ(s.max_connections, 4u);
    EXPECT_EQ(s.network_write_protection.mode, NetworkWriteProtection::all_except_listed);
    ASSERT_EQ(s.network_write_protection.nodes.size(), 2u);
    EXPECT_EQ(s.network_write_protection.nodes[1], (NodeAddress{2, 0xFF, 0}));
    EXPECT_TRUE(s.um_read_protection && s.dip_write_protection);
    ASSERT_EQ(s.memory.size(), 4u);
    EXPECT_EQ(s.memory[0].values, (std::vector<std::uint32_t>{1, 2, 3}));
    EXPECT_EQ(s.memory[0].where, "t.toml:21:1");
    EXPECT_EQ(s.memory[1].values, (std::vector<std::uint32_t>{1}));
    EXPECT_EQ(s.memory[2].values, (std::vector<std::uint32_t>{1, 0, 1}));
    EXPECT_EQ(s.memory[3].values, (std::vector<std::uint32_t>{0x12345678}));
    EXPECT_TRUE(s.inject.battery_error);
    ASSERT_EQ(s.inject.fal.size(), 2u);
    EXPECT_EQ(s.inject.fal[0].message, "JAM");
    EXPECT_EQ(s.inject.fal[1].number, 6);
    EXPECT_EQ(s.inject.fals->number, 9);
    EXPECT_EQ(*s.inject.messages[7], "bye");
    EXPECT_FALSE(s.inject.messages[3].has_value());
    EXPECT_EQ(s.inject.errors, (std::vector<std::uint16_t>{0x0203}));
    EXPECT_TRUE(validate(s).has_value());
}

TEST(FinsdSettings, UmPasswordIsPrintableAsciiUpTo16) {
    EXPECT_EQ(load("[protection]\npassword = \"PLC-2026\"\n").um_password, "PLC-2026");
    EXPECT_NE(error_of("[protection]\npassword = \"\"\n").find("1-16 printable"),
              std::string::npos);
    EXPECT_NE(error_of("[protection]\npassword = \"12345678901234567\"\n").find("1-16"),
              std::string::npos);
}

TEST(FinsdSettings, AFailedLoadChangesNothing) {
    Settings s;
    auto r = load_config_text("profile = \"cs1h\"\n[network]\nport = -1\n", "t.toml", s);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "t.toml:3:1: network.port: -1 is not 0-65535");
    EXPECT_EQ(s.profile, "cj2h");
}

TEST(FinsdSettings, ErrorsNameTheKeyAndPosition) {
    EXPECT_EQ(error_of("[network]\nnode = 255\n"), "t.toml:2:1: network.node: 255 is not 0-254");
    EXPECT_EQ(error_of("network = 1\n"), "t.toml:1:1: network: must be a table");
    EXPECT_EQ(error_of("[memory]\n\"D0\" = []\n"), "t.toml:2:1: memory.\"D0\": empty array");
    EXPECT_EQ(error_of("[memory]\n\"D0\" = 65536\n"),
              "t.toml:2:1: memory.\"D0\": word values are integers -32768..65535");
    EXPECT_EQ(error_of("[inject]\nerrors = [0x9999]\n"),
              "t.toml:2:1: inject.errors[0]: not an error code of W342 5-3-27");
    EXPECT_EQ(error_of("[inject]\nfals = { message = \"x\" }\n"),
              "t.toml:2:1: inject.fals.number: missing");
    EXPECT_EQ(error_of("data_dir = \"\"\n"), "t.toml:1:1: data_dir: must not be empty");
    EXPECT_EQ(error_of("[protection]\nnodes = [\"1.1\", \"x\"]\n"),
              "t.toml:2:1: protection.nodes[1]: must be \"network.node\" (network 0-127, node "
              "1-254 or *)");
    EXPECT_NE(error_of("a = [").find("t.toml:1:"), std::string::npos);
}

// [memory]'s { TYPE = value } takes src/typed's formats, ranges and words (the table
// behind fins --as, the web API and fins-bridge's tag types).
TEST(FinsdSettings, TypedValuesAreTheSharedFormats) {
    EXPECT_EQ(error_of("[memory]\n\"D0\" = { flaot = 1 }\n"),
              "t.toml:2:1: memory.\"D0\": 'flaot' is not a value type: int16, uint16, int32, "
              "uint32, float, double, bcd, bcd32 or string");
    EXPECT_EQ(error_of("[memory]\n\"D0\" = { hex = 1 }\n"),
              "t.toml:2:1: memory.\"D0\": 'hex' is not a value type: int16, uint16, int32, "
              "uint32, float, double, bcd, bcd32 or string");
    EXPECT_EQ(error_of("[memory]\n\"D0\" = { int16 = 1.5 }\n"),
              "t.toml:2:1: memory.\"D0\".int16: must be an integer");
    EXPECT_EQ(error_of("[memory]\n\"D0\" = { double = \"x\" }\n"),
              "t.toml:2:1: memory.\"D0\".double: must be a number");
    EXPECT_EQ(error_of("[memory]\n\"D0\" = { uint32 = [1, -1] }\n"),
              "t.toml:2:1: memory.\"D0\".uint32: -1 is out of range for uint32 (0 to 4294967295)");
    EXPECT_EQ(error_of("[memory]\n\"D0\" = { int16 = 32768 }\n"),
              "t.toml:2:1: memory.\"D0\".int16: 32768 is out of range for int16 (-32768 to 32767)");
    EXPECT_EQ(error_of("[memory]\n\"D0\" = { float = 1e39 }\n"),
              "t.toml:2:1: memory.\"D0\".float: 1e+39 is out of range for float");

    const Settings s = load(R"([memory]
"D0" = { int32 = [-5, 70000] }
"D10" = { float32 = 1.5 }
"D20" = { float = 1.5 }
"D30" = { bcd32 = 12345678 }
"D40" = { string = "ABC" }
)");
    ASSERT_EQ(s.memory.size(), 5u);
    using WordValues = std::vector<std::uint32_t>;
    EXPECT_EQ(s.memory[0].values, (WordValues{0xFFFB, 0xFFFF, 0x1170, 0x0001}));
    EXPECT_EQ(s.memory[1].values, (WordValues{0x0000, 0x3FC0}));  // "float32" is "float"
    EXPECT_EQ(s.memory[2].values, s.memory[1].values);
    EXPECT_EQ(s.memory[3].values, (WordValues{0x5678, 0x1234}));
    EXPECT_EQ(s.memory[4].values, (WordValues{0x4142, 0x4300}));
}

TEST(FinsdSettings, ParsersOfModesProtectionsAndNodes) {
    EXPECT_EQ(parse_mode("stop"), plc::OperatingMode::program);
    EXPECT_EQ(parse_mode("RUN"), std::nullopt);
    EXPECT_EQ(parse_protection("listed"), NetworkWriteProtection::listed);
    EXPECT_EQ(parse_protection("all_except_listed"), std::nullopt);
    EXPECT_EQ(parse_node("0.254"), (NodeAddress{0, 254, 0}));
    EXPECT_EQ(parse_node("127.*"), (NodeAddress{127, 0xFF, 0}));
    for (const char* bad : {"", ".", "1", "1.", ".1", "128.1", "1.0", "1.255", "1.2.3", "a.b",
                            "-1.2", "1.+2", " 1.2"})
        EXPECT_EQ(parse_node(bad), std::nullopt) << bad;
}

TEST(FinsdSettings, FlagsOverrideTheFile) {
    Settings s = load(
        "profile = \"cj1m\"\n[network]\nport = 1\nudp = false\n"
        "[protection]\nnetwork_write = \"all\"\nnodes = [\"1.1\"]\n");
    Overrides o;
    o.profile = "cp1h";
    o.port = 2;
    o.udp = true;
    o.network_write_protection = "listed";
    o.protect_nodes = {"3.3", "4.*"};
    o.dip_write_protection = true;
    ASSERT_TRUE(apply_overrides(o, s).has_value());
    EXPECT_EQ(s.profile, "cp1h");
    EXPECT_EQ(s.port, 2);
    EXPECT_TRUE(s.udp);
    EXPECT_EQ(s.network_write_protection.mode, NetworkWriteProtection::listed);
    EXPECT_EQ(s.network_write_protection.nodes,
              (std::vector<NodeAddress>{{3, 3, 0}, {4, 0xFF, 0}}));
    EXPECT_TRUE(s.dip_write_protection);
    Overrides bad;
    bad.protect_nodes = {"3"};
    EXPECT_EQ(apply_overrides(bad, s).error().rfind("--protect-node: '3'", 0), 0u);
    bad = {};
    bad.node = 0;
    EXPECT_FALSE(apply_overrides(bad, s));
}

TEST(FinsdSettings, ValidationAcrossKeys) {
    Settings s;
    s.profile = "cj3";
    EXPECT_EQ(validate(s).error(),
              "profile: unknown 'cj3' (known: cj2h, cs1h, cs1h-lcb, cj1m, cp1h, nx102)");
    s = {};
    s.network_write_protection.mode = NetworkWriteProtection::listed;
    EXPECT_FALSE(validate(s));
    s.network_write_protection.nodes = {NodeAddress{0, 1, 0}};
    EXPECT_TRUE(validate(s));
    s.log_level = "loud";
    EXPECT_FALSE(validate(s));
}

TEST(FinsdSettings, InitialMemoryIsCheckedAgainstTheModel) {
    const Settings s = load("[memory]\n\"E0_0\" = 1\n");
    plc::Plc cj2h;
    plc::Plc cj1m(*plc::find_profile("cj1m"));
    EXPECT_TRUE(check_initial_memory(s.memory, cj2h.memory()).has_value());
    const auto r = check_initial_memory(s.memory, cj1m.memory());
    ASSERT_FALSE(r);
    EXPECT_EQ(
        r.error().rfind("t.toml:2:1: memory.\"E0_0\": cannot be written on the CJ1M_CPU13", 0), 0u)
        << r.error();
}

// Choice: [memory] never overwrites restored retained memory; cleared areas get their
// initial values at every start.
TEST(FinsdSettings, RetainedEntriesAreSkippedOnARestoredState) {
    const Settings s = load(R"([memory]
"D0" = 1
"H0" = 2
"E3_0" = 3
"C5" = 4
"A510" = 5
"CIO0" = 6
"W0" = 7
"T5" = 8
"A448" = 9
"A509" = [10, 11]
)");
    std::vector<bool> retained;
    for (const auto& e : s.memory)
        retained.push_back(writes_retained_memory(e));
    EXPECT_EQ(retained,
              (std::vector<bool>{true, true, true, true, true, false, false, false, false, true}));
    plc::Plc fresh;
    EXPECT_EQ(apply_initial_memory(s.memory, fresh.memory(), false), 10u);
    EXPECT_EQ(fresh.memory().words(Region::dm)[0], 1);
    EXPECT_EQ(fresh.memory().words(Region::auxiliary)[510], 11);  // A509-A510 after A510
    plc::Plc restored;
    restored.memory().words(Region::dm)[0] = 100;
    EXPECT_EQ(apply_initial_memory(s.memory, restored.memory(), true), 4u);
    EXPECT_EQ(restored.memory().words(Region::dm)[0], 100);
    EXPECT_EQ(restored.memory().words(Region::cio)[0], 6);
    EXPECT_EQ(restored.memory().words(Region::timer_counter)[5], 8);
    EXPECT_EQ(restored.memory().words(Region::auxiliary)[448], 9);
}

}  // namespace
}  // namespace fins::finsd
