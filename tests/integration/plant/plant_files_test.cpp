// Each plant CPU Unit's file memory (README "A plant of several networks"): with a
// data_dir its Memory Card, EM file memory and cassette live in <data_dir>/card, em and
// cassette and survive a restart, as a single node's do; [plc.files] sets each CPU Unit's
// devices; the single node's [files] in a plant is named as ignored.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

namespace fs = std::filesystem;

const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";

// `fins` against the unit bound to `host` port 9611.
RunResult fins_at(const std::string& host, std::vector<std::string> args) {
    std::vector<std::string> argv{fins_bin, "--host", host, "--port", "9611", "--timeout", "5"};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

bool has(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// Two CPU Units on loopback addresses no other test binds: "kept" (127.0.65.1) and
// "temp" (127.0.66.1); `kept_extra` and `temp_extra` are more keys and tables of each.
std::string plant(const std::string& kept_extra, const std::string& temp_extra) {
    return R"(
[[plc]]
name = "kept"
)" + kept_extra +
           R"(
  [[plc.ethernet]]
  network = 1
  bind = "127.0.65.1"
  port = 9611
[[plc]]
name = "temp"
)" + temp_extra +
           R"(
  [[plc.ethernet]]
  network = 2
  bind = "127.0.66.1"
  port = 9611
)";
}

// W342 5-3-33 FILE WRITE: a file written to a plant CPU Unit's Memory Card is in
// <data_dir>/card and is read back, byte for byte, after the plant stops and starts again.
// The CPU Unit without data_dir keeps its files in a temporary root for the run only.
TEST(PlantFiles, W342_5_3_33_FileOnAPlantCpuUnitsCardSurvivesARestart) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-files");
    const fs::path data = dir.path() / "kept";
    const auto config =
        dir.write("plant.toml", plant("data_dir = \"" + data.string() + "\"\n", ""));
    std::string content(5000, '\0');
    for (std::size_t i = 0; i < content.size(); ++i)
        content[i] = static_cast<char>((i * 7 + 3) & 0xFF);
    const auto local = dir.write("in.bin", content);
    {
        Finsd d({"--config", config});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto r = fins_at("127.0.65.1", {"files", "put", local, "/DATA.BIN"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        r = fins_at("127.0.66.1", {"files", "put", local, "/TEMP.BIN"});
        ASSERT_EQ(r.exit_code, 0) << r.err;  // without data_dir: still a card
        const auto back = (dir.path() / "temp-back.bin").string();
        r = fins_at("127.0.66.1", {"files", "get", "/TEMP.BIN", back});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_EQ(slurp(back), content);
        EXPECT_EQ(d.stop().exit_code, 0);
    }
    EXPECT_EQ(slurp(data / "card" / "DATA.BIN"), content);
    Finsd d({"--config", config});
    ASSERT_TRUE(d.started()) << d.result().err;
    const auto back = (dir.path() / "back.bin").string();
    auto r = fins_at("127.0.65.1", {"files", "get", "/DATA.BIN", back});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(back), content);
    // The temporary card went with the previous run: 2006 read not possible, file missing.
    r = fins_at("127.0.66.1", {"files", "get", "/TEMP.BIN", (dir.path() / "x").string()});
    EXPECT_EQ(r.exit_code, 4) << r.out << r.err;
    EXPECT_TRUE(has(r.err, "2006")) << r.err;
    EXPECT_EQ(d.stop().exit_code, 0);
}

// A device directory of a plant CPU Unit that is a symlink to no directory refuses the
// start (exit 3) naming the CPU Unit and the path, as a single node's does.
TEST(PlantFiles, SymlinkedCardToNoDirectoryRefusesTheStartNamingTheCpuUnit) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-files");
    const fs::path data = dir.path() / "kept";
    fs::create_directories(data);
    std::ofstream(dir.path() / "not-a-dir") << "x";
    fs::create_symlink(dir.path() / "not-a-dir", data / "card");
    Finsd d(
        {"--config", dir.write("plant.toml", plant("data_dir = \"" + data.string() + "\"\n", ""))});
    ASSERT_FALSE(d.started());
    EXPECT_EQ(d.result().exit_code, 3);
    EXPECT_TRUE(has(d.result().err,
                    "plc \"kept\": file memory: " + (data / "card").string() + " is a symlink to"))
        << d.result().err;
}

// W342 5-3-43 (22 20, the CP1H's cassette) and 5-3-32 (22 01 on the card): [plc.files]
// sets each CPU Unit's devices against its profile's. "kept", a CP1H, has its cassette
// taken out; "temp", a CJ2H, has no card but EM file memory: each answers 2301 (file
// device missing) for its own missing device only (22 20 in PROGRAM mode, where it runs).
TEST(PlantFiles, W342_5_3_43_EachCpuUnitHasItsOwnCassetteAndCard) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-files");
    Finsd d(
        {"--config",
         dir.write("plant.toml",
                   plant("profile = \"cp1h\"\nmode = \"program\"\n[plc.files]\ncassette = false\n",
                         "[plc.files]\ncard = false\nem_file_bank = 20\n"))});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto r = fins_at("127.0.65.1", {"files", "cassette", "type"});
    EXPECT_EQ(r.exit_code, 4) << r.out;
    EXPECT_TRUE(has(r.err, "2301")) << r.err;
    r = fins_at("127.0.66.1", {"files", "ls"});
    EXPECT_EQ(r.exit_code, 4) << r.out;
    EXPECT_TRUE(has(r.err, "2301")) << r.err;
    // Its EM file memory from bank 20 on (W342 5-3-32: em:); none without em_file_bank.
    r = fins_at("127.0.66.1", {"files", "ls", "em:"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
}

// The single node's [files] describes no CPU Unit of a plant: finsd says it is ignored
// and that a [[plc]] takes its own [plc.files]; the CPU Units keep their profile's card.
TEST(PlantFiles, SingleNodeFilesTableInAPlantIsNamedAsIgnored) {
    const FixedPorts fixed_ports;  // 127.0.x.y:9611 (finsd_run.hpp)
    ScratchDir dir("plant-files");
    Finsd d({"--config", dir.write("plant.toml", "[files]\ncard = false\n" + plant("", ""))});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_EQ(fins_at("127.0.65.1", {"files", "ls"}).exit_code, 0);
    const auto err = d.stop().err;
    EXPECT_TRUE(has(err, "[files] (a [[plc]] takes its own [plc.files])")) << err;
}

}  // namespace
}  // namespace fins::test
