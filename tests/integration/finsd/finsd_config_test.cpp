// finsd --config FILE and its flags, as a user runs them: the profile a file selects,
// initial memory, protections, flags overriding the file, configuration errors (exit 2,
// naming the key and line) and state-file errors (exit 3).
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

const CommandCode memory_read{0x01, 0x01};
const CommandCode parameter_read{0x02, 0x01};

// 01 01 of one word at `code` word 0.
std::vector<std::uint8_t> one_word(std::uint8_t code) {
    return {code, 0x00, 0x00, 0x00, 0x00, 0x01};
}

TEST(FinsdConfig, ProfilesFromTheFileDecideTheAreas) {
    ScratchDir dir("cfg");
    {
        Finsd d({"--config", dir.write("cj1m.toml", "profile = \"cj1m\"\n")});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client();
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(end_code(*c, memory_read, one_word(0xA0)), 0x1101u);  // CJ1M has no EM
        EXPECT_EQ(end_code(*c, memory_read, one_word(0x82)), 0x0000u);
        EXPECT_EQ(end_code(*c, memory_read, one_word(0x80)), 0x0000u);  // CV codes: yes
    }
    {
        Finsd d({"--config", dir.write("nx.toml", "profile = \"NX102-9000\"\n")});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client(true);
        ASSERT_NE(c, nullptr);
        // W596 2-2: 02 01 is not in the NX subset.
        EXPECT_EQ(end_code(*c, parameter_read, {0x80, 0x10, 0x00, 0x00, 0x00, 0x01}), 0x0401u);
        EXPECT_EQ(end_code(*c, memory_read, one_word(0xA3)), 0x0000u);  // E3 exists
        EXPECT_EQ(end_code(*c, memory_read, one_word(0xA4)), 0x1101u);  // E4 does not
        EXPECT_EQ(end_code(*c, memory_read, one_word(0xB3)), 0x1101u);  // no A area
    }
    {
        Finsd d({"--config", dir.write("cs1h.toml", "profile = \"cs1h\"\n")});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client();
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(end_code(*c, memory_read, one_word(0xAC)), 0x0000u);  // EC: the 13th bank
        EXPECT_EQ(end_code(*c, memory_read, one_word(0xAD)), 0x1101u);
        EXPECT_EQ(end_code(*c, memory_read, one_word(0x50)), 0x1101u);  // CJ2-only code
    }
}

TEST(FinsdConfig, InitialMemoryIsVisible) {
    ScratchDir dir("cfg");
    const std::string cfg = R"(
profile = "cj2h"
[memory]
"D100" = [1, 2, 3]
"H0" = 0x1234
"CIO10.13" = true
"W0.0" = [true, false, true]
"E3_100" = -1
)";
    Finsd d({"--config", dir.write("m.toml", cfg)});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(words_of(*c, "D100", 3), (std::vector<std::uint16_t>{1, 2, 3}));
    EXPECT_EQ(words_of(*c, "H0", 1), (std::vector<std::uint16_t>{0x1234}));
    EXPECT_EQ(words_of(*c, "CIO10", 1), (std::vector<std::uint16_t>{0x2000}));
    EXPECT_EQ(words_of(*c, "W0", 1), (std::vector<std::uint16_t>{0x0005}));
    EXPECT_EQ(words_of(*c, "E3_100", 1), (std::vector<std::uint16_t>{0xFFFF}));
}

TEST(FinsdConfig, FlagsOverrideTheFile) {
    ScratchDir dir("cfg");
    const std::string file = dir.write("f.toml", R"(
profile = "cj1m"
[protection]
network_write = "all"
[memory]
"D0" = 7
)");
    Finsd d({"--config", file, "--profile", "cj2h", "--network-write-protection", "off"});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(end_code(*c, memory_read, one_word(0xA0)), 0x0000u);  // CJ2H: EM is there
    EXPECT_TRUE(c->write_words(addr("D1"), std::vector<std::uint16_t>{9}).has_value());
    EXPECT_EQ(words_of(*c, "D0", 2), (std::vector<std::uint16_t>{7, 9}));
}

TEST(FinsdConfig, NetworkWriteProtectionFromTheFile) {
    ScratchDir dir("cfg");
    {
        Finsd d({"--config", dir.write("all.toml", "[protection]\nnetwork_write = \"all\"\n")});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client();
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(end_code(*c, CommandCode{0x01, 0x02}, {0x82, 0, 0, 0, 0, 1, 0x12, 0x34}),
                  0x2102u);
        EXPECT_EQ(end_code(*c, memory_read, one_word(0x82)), 0x0000u);
    }
    {
        // The client's own source node: listed -> refused; another node listed -> allowed.
        Finsd d(
            {"--config",
             dir.write("x.toml", "[protection]\nnetwork_write = \"listed\"\nnodes = [\"5.5\"]\n")});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client();
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(end_code(*c, CommandCode{0x01, 0x02}, {0x82, 0, 0, 0, 0, 1, 0x12, 0x34}), 0u);
        const auto me = c->source();
        Finsd e({"--network-write-protection", "listed", "--protect-node",
                 std::to_string(me.network) + "." + std::to_string(me.node)});
        ASSERT_TRUE(e.started()) << e.result().err;
        auto c2 = e.client();
        ASSERT_NE(c2, nullptr);
        EXPECT_EQ(end_code(*c2, CommandCode{0x01, 0x02}, {0x82, 0, 0, 0, 0, 1, 0x12, 0x34}),
                  0x2102u);
    }
}

TEST(FinsdConfig, StartupModeAndInjections) {
    ScratchDir dir("cfg");
    // 03 07 PROGRAM AREA WRITE is refused in RUN (2206) before its parameters are read.
    const CommandCode program_write{0x03, 0x07};
    const std::vector<std::uint8_t> params{0xFF, 0xFF, 0, 0, 0, 0, 0x80, 0x00};
    {
        Finsd d({});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client();
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(end_code(*c, program_write, params), 0x2206u);
        auto r = c->send_raw(memory_read, one_word(0x82));
        ASSERT_TRUE(r.has_value());
        EXPECT_FALSE(r->code.non_fatal_cpu_error());
    }
    Finsd d(
        {"--config", dir.write("i.toml", "mode = \"program\"\n[inject]\nbattery_error = true\n")});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    EXPECT_NE(end_code(*c, program_write, params), 0x2206u);
    auto r = c->send_raw(memory_read, one_word(0x82));
    ASSERT_TRUE(r.has_value());
    EXPECT_TRUE(r->code.ok());
    EXPECT_TRUE(r->code.non_fatal_cpu_error());  // 0040: the injected battery error
}

struct BadConfig {
    const char* text;
    const char* where;  // file position the message starts with
    const char* what;   // the key and the complaint
};

TEST(FinsdConfig, ConfigErrorsExit2NamingKeyAndLine) {
    ScratchDir dir("cfg");
    const BadConfig cases[] = {
        {"profile = \"cj3\"\n", "", "profile: unknown 'cj3' (known: cj2h, cs1h"},
        {"\n\nprofle = \"cj2h\"\n", "bad.toml:3:1: ", "profle: unknown key"},
        {"[network]\nport = 70000\n", "bad.toml:2:1: ", "network.port: 70000 is not 0-65535"},
        {"[network]\nnode = \"ten\"\n", "bad.toml:2:1: ", "network.node: must be an integer"},
        {"[network]\nspeed = 1\n", "bad.toml:2:1: ", "network.speed: unknown key"},
        {"mode = \"halt\"\n", "bad.toml:1:1: ", "mode: 'halt' is not program, monitor or run"},
        {"[protection]\nnetwork_write = \"some\"\n", "bad.toml:2:1: ",
         "protection.network_write: 'some' is not off, all, listed or all-except-listed"},
        {"[protection]\nnodes = [\"1.300\"]\n", "bad.toml:2:1: ", "protection.nodes[0]: must be"},
        {"[protection]\nnetwork_write = \"listed\"\n", "", "protection.nodes: empty"},
        {"[memory]\n\"D100\" = \"x\"\n", "bad.toml:2:1: ", "memory.\"D100\": word values"},
        {"[memory]\n\"CIO1.2\" = 5\n", "bad.toml:2:1: ", "memory.\"CIO1.2\": bit values"},
        {"[memory]\n\"Q5\" = 1\n", "bad.toml:2:1: ", "memory.\"Q5\": not a PLC address"},
        {"[memory]\n\"D32767\" = [1, 2]\n",
         "bad.toml:2:1: ", "memory.\"D32767\": cannot be written"},
        {"[memory]\n\"A0\" = 1\n", "bad.toml:2:1: ", "memory.\"A0\": cannot be written"},
        {"[inject]\nfal = [{ number = 600 }]\n",
         "bad.toml:2:", "inject.fal[0].number: 600 is not 1-511"},
        {"[inject]\nmessages = { 9 = \"x\" }\n",
         "bad.toml:2:", "inject.messages.9: message numbers are 0-7"},
        {"[inject]\nfals = { number = 3, message = \"12345678901234567\" }\n",
         "bad.toml:2:1: ", "inject.fals.message: longer than 16 characters"},
        {"[network]\nudp = false\ntcp = false\n", "",
         "network: udp and tcp are both off and no serial port is in hostlink mode"},
        {"profile = \n", "bad.toml:1:", ""},  // TOML syntax error
    };
    for (const auto& c : cases) {
        Finsd d({"--config", dir.write("bad.toml", c.text)});
        ASSERT_FALSE(d.started()) << c.text;
        EXPECT_EQ(d.result().exit_code, 2) << c.text << d.result().err;
        // "finsd: <file>:<line>:<column>: <key>: <complaint>"
        const std::string prefix = *c.where != 0 ? "finsd: " + dir.path().string() + "/" + c.where
                                                 : std::string("finsd: ") + c.what;
        EXPECT_EQ(d.result().err.rfind(prefix, 0), 0u)
            << c.text << "\nexpected: " << prefix << "\nstderr: " << d.result().err;
        EXPECT_NE(d.result().err.find(c.what), std::string::npos) << d.result().err;
    }
    Finsd missing({"--config", (dir.path() / "nope.toml").string()});
    EXPECT_EQ(missing.result().exit_code, 2);
    Finsd flag({"--mode", "sideways"});
    EXPECT_EQ(flag.result().exit_code, 2);
    EXPECT_NE(flag.result().err.find("--mode"), std::string::npos);
}

// A wrong path must end in a message, not in a finsd reading until memory runs out:
// /dev/zero never ends, so without the bound this test would not end either.
TEST(FinsdConfig, AConfigurationThatNeverEndsIsRefusedAtItsBound) {
    Finsd zero({"--config", "/dev/zero"});
    ASSERT_FALSE(zero.started());
    EXPECT_EQ(zero.result().exit_code, 2);
    EXPECT_NE(zero.result().err.find("/dev/zero: larger than 16 MiB: not a configuration file"),
              std::string::npos)
        << zero.result().err;
    Finsd scenario({"--scenario", "/dev/zero"});
    ASSERT_FALSE(scenario.started());
    EXPECT_EQ(scenario.result().exit_code, 2);
    EXPECT_NE(scenario.result().err.find("/dev/zero: larger than 16 MiB"), std::string::npos)
        << scenario.result().err;
    Finsd token({"--http", "127.0.0.1:0", "--http-token-file", "/dev/zero"});
    ASSERT_FALSE(token.started());
    EXPECT_NE(token.result().err.find("--http-token-file /dev/zero: cannot read it: larger "
                                      "than 64 KiB"),
              std::string::npos)
        << token.result().err;
}

TEST(FinsdConfig, StateFileErrorsExit3) {
    ScratchDir dir("cfg");
    const std::string data = (dir.path() / "data").string();
    {
        Finsd d({"--profile", "cj2h", "--data-dir", data});
        ASSERT_TRUE(d.started()) << d.result().err;
        Finsd twin({"--profile", "cj2h", "--data-dir", data});  // the lock
        EXPECT_EQ(twin.result().exit_code, 3);
        EXPECT_NE(twin.result().err.find("in use"), std::string::npos) << twin.result().err;
        EXPECT_EQ(d.stop().exit_code, 0);
    }
    Finsd foreign({"--profile", "cs1h", "--data-dir", data});
    EXPECT_EQ(foreign.result().exit_code, 3);
    EXPECT_NE(foreign.result().err.find("another PLC profile"), std::string::npos)
        << foreign.result().err;
    std::filesystem::resize_file(dir.path() / "data" / "finsd.state", 4096 + 100);
    Finsd damaged({"--profile", "cj2h", "--data-dir", data});
    EXPECT_EQ(damaged.result().exit_code, 3);
    EXPECT_NE(damaged.result().err.find("damaged"), std::string::npos) << damaged.result().err;
}

// Choice: [memory] never overwrites retained data; entries in cleared areas are written
// at every start.
TEST(FinsdConfig, InitialMemoryOnlyOnANewStateForRetainedAreas) {
    ScratchDir dir("cfg");
    const std::string cfg =
        dir.write("m.toml", "profile = \"cj2h\"\ndata_dir = \"" + (dir.path() / "data").string() +
                                "\"\n[memory]\n\"D100\" = 1\n\"W0\" = 2\n");
    {
        Finsd d({"--config", cfg});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client();
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(words_of(*c, "D100", 1), (std::vector<std::uint16_t>{1}));
        ASSERT_TRUE(c->write_words(addr("D100"), std::vector<std::uint16_t>{99}).has_value());
        ASSERT_TRUE(c->write_words(addr("W0"), std::vector<std::uint16_t>{98}).has_value());
        EXPECT_EQ(d.stop().exit_code, 0);
    }
    Finsd d({"--config", cfg});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(words_of(*c, "D100", 1), (std::vector<std::uint16_t>{99}));
    EXPECT_EQ(words_of(*c, "W0", 1), (std::vector<std::uint16_t>{2}));
}

TEST(FinsdConfig, EveryExampleConfigStarts) {
    const auto examples = std::filesystem::path(FINS_SOURCE_DIR) / "examples";
    ASSERT_TRUE(std::filesystem::is_directory(examples));
    int n = 0;
    for (const auto& entry : std::filesystem::directory_iterator(examples)) {
        if (entry.path().extension() != ".toml") continue;
        // A plant's example binds its own addresses: plant_example_test.cpp runs it.
        std::ifstream file(entry.path());
        const std::string text{std::istreambuf_iterator<char>(file), {}};
        if (text.find("[[plc]]") != std::string::npos) continue;
        ++n;
        // The examples leave data_dir and control commented out; --port 0, --bind and
        // --node override theirs (node 1: what a UDP client derives on loopback).
        Finsd d({"--config", entry.path().string(), "--bind", "127.0.0.1", "--node", "1"});
        ASSERT_TRUE(d.started()) << entry.path() << ": " << d.result().err;
        auto c = d.client();
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(end_code(*c, memory_read, one_word(0x82)), 0x0000u) << entry.path();
    }
    EXPECT_GE(n, 5);
}

}  // namespace
}  // namespace fins::test
