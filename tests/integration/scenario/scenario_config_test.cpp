// Scenarios in finsd's configuration (issue 19): every bad scenario stops finsd with
// exit 2 and "file:line:col: message" before it listens; --scenario FILE; a good one starts.
#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

struct BadScenario {
    const char* text;
    const char* where;  // "bad.toml:LINE:COL: "
    const char* what;
};

TEST(ScenarioConfig, BadScenariosExit2WithTheirPosition) {
    ScratchDir dir("scenario-cfg");
    const BadScenario cases[] = {
        {"[scenario]\nseed = 1\ntick = 5\n", "bad.toml:3:1: ", "scenario.tick: unknown key"},
        {"[scenario]\ntime = \"fast\"\n",
         "bad.toml:2:8: ", "scenario.time: 'fast' is not real or virtual"},
        {"[scenario]\ncompute = \"gpu\"\n",
         "bad.toml:2:11: ", "scenario.compute: 'gpu' is not auto, io or thread"},
        {"[[scenario.signal]]\naddress = \"D0\"\nkind = \"sine\"\nfrequency = 3\n",
         "bad.toml:4:1: ", "scenario.signal[0].frequency: unknown key for kind = \"sine\""},
        {"[[scenario.signal]]\naddress = \"D0\"\nkind = \"wobble\"\n",
         "bad.toml:3:8: ", "scenario.signal[0].kind: 'wobble' is not constant, sine"},
        {"[[scenario.signal]]\naddress = \"D0\"\ntype = \"int8\"\nkind = \"constant\"\n",
         "bad.toml:3:8: ", "scenario.signal[0].type: 'int8' is not int16"},
        {"[[scenario.signal]]\naddress = \"A10\"\nkind = \"constant\"\n",
         "bad.toml:2:11: ", "A10 is in a read-only area"},
        {"profile = \"cj1m\"\n[[scenario.signal]]\naddress = \"E3_0\"\nkind = \"constant\"\n",
         "bad.toml:3:11: ", "has no E3_0"},
        {"[[scenario.signal]]\naddress = \"D0\"\ntype = \"bool\"\nkind = \"constant\"\n",
         "bad.toml:2:11: ", "type \"bool\" needs a bit address"},
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = \"D2\"\n[[scenario.link]]\naddress = "
         "\"D2\"\nexpr = \"D1 + 1\"\n",
         "bad.toml:1:1: ", "the links form a cycle: D1 -> D2 -> D1"},
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = \"2 * D100 +\"\n",
         "bad.toml:3:19: ", "expression ends where a value is expected"},
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = \"2 * Q5\"\n",
         "bad.toml:3:13: ", "'Q5' is neither an address nor a name"},
        {"[[scenario.signal]]\naddress = \"D0\"\nkind = \"constant\"\n[[scenario.event]]\nat_s = "
         "1\nfault = \"stuck\"\naddress = \"D7\"\n",
         "bad.toml:7:11: ", "D7 is not a tag of this scenario"},
        {"[[scenario.event]]\nat_s = 1\nfault = \"meltdown\"\n",
         "bad.toml:3:9: ", "scenario.event[0].fault: 'meltdown' is not stuck"},
        // [[scenario.loop]]: a Loop Control Board ITEM answered from memory.
        {"[[scenario.loop]]\nblock = 1\nitem = 6\naddress = \"D0\"\n",
         "bad.toml:1:1: ", "the CJ2H-CPU68-EIP has no Loop Control Board (02 40)"},
        {"profile = \"cs1h-lcb\"\n[[scenario.loop]]\nblock = 7\nitem = 6\naddress = \"D0\"\n",
         "bad.toml:2:1: ", "block 7 is not a function block of the board"},
        {"profile = \"cs1h-lcb\"\n[[scenario.loop]]\nblock = 100\nitem = 12\naddress = "
         "\"D0\"\n",
         "bad.toml:2:1: ", "block 100 (Step Ladder Program) has no readable ITEM 12"},
        {"profile = \"cs1h-lcb\"\n[[scenario.loop]]\nblock = 1\nitem = 6\naddress = "
         "\"CIO0.00\"\n",
         "bad.toml:5:11: ", "CIO0.00 is a bit"},
        {"[[scenario.loop]]\nblock = 1\naddress = \"D0\"\n",
         "bad.toml:1:1: ", "scenario.loop[0]: item: missing"},
        // Positions inside a multi-line string, after escapes, in characters (issue 26).
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = \"\"\"\n2 * D100 +\n  Q5\"\"\"\n",
         "bad.toml:5:3: ", "'Q5' is neither an address nor a name"},
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = \"1 +\\t\\tQ5\"\n",
         "bad.toml:3:16: ", "'Q5' is neither an address nor a name"},
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = '1 + \\t Q5'\n",
         "bad.toml:3:13: ", "unexpected character '\\'"},
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = \"2 * D2\xC3\xA9\"\n",
         "bad.toml:3:15: ", "unexpected character '\xC3\xA9'"},
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = \"\\u00E9\\u00E9 + 1\"\n",
         "bad.toml:3:9: ", "unexpected character '\xC3\xA9'"},
        {"[[scenario.link]]\naddress = \"D1\"\nexpr = \"D40000 + 1\"\n",
         "bad.toml:3:9: ", "D40000 is out of range: D0-D32767"},
        {"[[scenario.signal]]\naddress = \"D40000\"\nkind = \"constant\"\n",
         "bad.toml:2:11: ", "D40000 is out of range: D0-D32767"},
        // duty: only for a square wave, a fraction 0-1.
        {"[[scenario.signal]]\naddress = \"D0\"\nkind = \"sine\"\nduty = 0.2\n",
         "bad.toml:4:1: ", "scenario.signal[0].duty: unknown key for kind = \"sine\""},
        {"[[scenario.signal]]\naddress = \"D0\"\nkind = \"square\"\nduty = 1.5\n",
         "bad.toml:4:8: ", "scenario.signal[0].duty: 1.5 is not a fraction 0-1"},
        {"[[scenario.signal]]\naddress = \"D0\"\nkind = \"square\"\nduty = -0.1\n",
         "bad.toml:4:8: ", "scenario.signal[0].duty: -0.1 is not a fraction 0-1"},
    };
    for (const auto& c : cases) {
        Finsd d({"--config", dir.write("bad.toml", c.text)});
        ASSERT_FALSE(d.started()) << c.text;
        EXPECT_EQ(d.result().exit_code, 2) << c.text << d.result().err;
        const std::string prefix = "finsd: " + dir.path().string() + "/" + c.where;
        EXPECT_EQ(d.result().err.rfind(prefix, 0), 0u)
            << c.text << "\nexpected: " << prefix << "\nstderr: " << d.result().err;
        EXPECT_NE(d.result().err.find(c.what), std::string::npos) << d.result().err;
    }
}

TEST(ScenarioConfig, ScenarioFileAndIncludedFilesNameTheirOwnFile) {
    ScratchDir dir("scenario-file");
    const auto bad = dir.write("bad-scenario.toml",
                               "[scenario]\ntime = \"virtual\"\n[[scenario.link]]\naddress = "
                               "\"D1\"\nexpr = \"abs(1, 2)\"\n");
    Finsd d({"--scenario", bad});
    ASSERT_FALSE(d.started());
    EXPECT_EQ(d.result().exit_code, 2);
    EXPECT_EQ(d.result().err.rfind("finsd: " + bad + ":5:9: abs() takes 1 argument", 0), 0u)
        << d.result().err;

    // A [scenario] table naming a file: errors in that file name it.
    dir.write("machine.toml",
              "[scenario]\n[[scenario.signal]]\naddress = \"A10\"\nkind = \"constant\"\n");
    Finsd included({"--config", dir.write("finsd.toml", "[scenario]\nfile = \"machine.toml\"\n")});
    ASSERT_FALSE(included.started());
    EXPECT_NE(included.result().err.find(dir.path().string() +
                                         "/machine.toml:3:11: A10 is in a read-only area"),
              std::string::npos)
        << included.result().err;

    Finsd missing({"--scenario", (dir.path() / "nope.toml").string()});
    EXPECT_EQ(missing.result().exit_code, 2);
    EXPECT_NE(missing.result().err.find("cannot read the file"), std::string::npos);

    const auto good = dir.write("good.toml",
                                "[scenario]\nseed = 42\ntime = \"virtual\"\n[[scenario.signal]]\n"
                                "address = \"D100\"\nkind = \"constant\"\nvalue = 7\n");
    Finsd ok({"--scenario", good});
    ASSERT_TRUE(ok.started()) << ok.result().err;
    EXPECT_EQ(ok.stop().exit_code, 0);
}

}  // namespace
}  // namespace fins::test
