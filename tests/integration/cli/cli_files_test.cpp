// `fins files` against a real finsd (W342 5-3-32 .. 5-3-42): a file copied from the
// card to the host and back is byte-identical, every verb's output, JSON and exit code
// (0 ok, 2 usage, 4 end code); and a file being replaced by 22 03 while finsd is
// SIGKILLed holds the old or the new content, never a mix.
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fins/commands/file_memory.hpp"
#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";

RunResult fins(const Finsd& d, std::vector<std::string> args) {
    std::vector<std::string> argv{fins_bin, "--port", std::to_string(d.port()), "--timeout", "5"};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

std::string random_bytes(std::size_t n, unsigned seed) {
    std::mt19937 gen(seed);
    std::string s(n, '\0');
    for (auto& c : s)
        c = static_cast<char>(gen());
    return s;
}

TEST(CliFiles, W342_5_3_33_PutGetRoundTripIsByteIdentical) {
    ScratchDir dir("cli-files");
    Finsd d({"--data-dir", (dir.path() / "data").string()});
    ASSERT_TRUE(d.started()) << d.result().err;
    const std::string content = random_bytes(100'000, 7);
    const auto local = dir.write("in.bin", content);
    auto r = fins(d, {"files", "put", local, "/DATA.BIN"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "put DATA.BIN (100000 bytes)\n");
    const auto back = (dir.path() / "back.bin").string();
    r = fins(d, {"files", "get", "card:\\data.bin", back});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(back), content);
    // The device directory holds the same bytes.
    EXPECT_EQ(slurp(dir.path() / "data/card/DATA.BIN"), content);
    // Put again without --force: 2107, exit 4; with --force it replaces.
    r = fins(d, {"files", "put", local, "/DATA.BIN"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("2107"), std::string::npos) << r.err;
    const auto small = dir.write("small.bin", "small");
    EXPECT_EQ(fins(d, {"files", "put", "--force", small, "/DATA.BIN"}).exit_code, 0);
    EXPECT_EQ(slurp(dir.path() / "data/card/DATA.BIN"), "small");
}

TEST(CliFiles, W342_5_3_32_EveryVerbWithJsonAndExitCodes) {
    ScratchDir dir("cli-files-verbs");
    Finsd d({"--data-dir", (dir.path() / "data").string()});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_EQ(fins(d, {"files", "mkdir", "/LOGS"}).exit_code, 0);
    const auto local = dir.write("a.txt", "hello");
    EXPECT_EQ(fins(d, {"files", "put", local, "/LOGS/A.TXT"}).exit_code, 0);
    auto r = fins(d, {"--json", "files", "ls", "/LOGS"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["files"].size(), 3U);  // ".", "..", A.TXT
    EXPECT_EQ(j["files"][2]["name"], "A.TXT");
    EXPECT_EQ(j["files"][2]["size"], 5);
    EXPECT_EQ(j["volume"], "MEMCARD");
    EXPECT_EQ(fins(d, {"files", "cp", "/LOGS/A.TXT", "/B.TXT"}).exit_code, 0);
    EXPECT_EQ(fins(d, {"files", "mv", "/B.TXT", "C.TXT"}).exit_code, 0);
    r = fins(d, {"--json", "files", "rm", "/C.TXT", "/NONE.TXT"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["deleted"], 1);
    EXPECT_EQ(fins(d, {"files", "rmdir", "/LOGS"}).exit_code, 4);  // not empty: 2108
    EXPECT_EQ(fins(d, {"files", "rm", "/LOGS/A.TXT"}).exit_code, 0);
    EXPECT_EQ(fins(d, {"files", "rmdir", "/LOGS"}).exit_code, 0);
    // save / compare / load of I/O memory, parameter area and program.
    EXPECT_EQ(fins(d, {"files", "save", "D0", "/D.IOM", "10"}).exit_code, 0);
    r = fins(d, {"--json", "files", "compare", "/D.IOM", "D0", "10"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["count"], 10);
    EXPECT_EQ(fins(d, {"files", "save", "plc-setup", "/P.STD"}).exit_code, 0);
    EXPECT_EQ(fins(d, {"files", "load", "/P.STD", "plc-setup"}).exit_code, 4);  // RUN: 2206
    EXPECT_EQ(fins(d, {"files", "save", "program", "/P.OBJ"}).exit_code, 0);
    // Usage errors exit 2 before anything is sent.
    EXPECT_EQ(fins(d, {"files", "put", local, "/TOOLONGNAME.TXT"}).exit_code, 2);
    EXPECT_EQ(fins(d, {"files", "save", "XYZ", "/Q.IOM", "1"}).exit_code, 2);
    EXPECT_EQ(fins(d, {"files", "format", "card"}).exit_code, 2);  // needs --yes
    // A missing file and a missing device: end codes, exit 4.
    r = fins(d, {"files", "get", "/NONE.TXT", (dir.path() / "x").string()});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("2006"), std::string::npos) << r.err;
    EXPECT_EQ(fins(d, {"files", "ls", "em:"}).exit_code, 4);  // 2301
    EXPECT_EQ(fins(d, {"files", "format", "card", "--yes"}).exit_code, 0);
    r = fins(d, {"--json", "files", "ls"});
    ASSERT_EQ(r.exit_code, 0);
    EXPECT_TRUE(nlohmann::json::parse(r.out)["files"].empty());
}

// Content number i: 1,900 bytes, the first two i, the rest i mod 251.
std::string version(std::size_t i) {
    std::string s(1900, static_cast<char>(i % 251));
    s[0] = static_cast<char>(i >> 8);
    s[1] = static_cast<char>(i & 0xFF);
    return s;
}
// 5-3-39: `files save` in the README table's order ("D100 10" then the file) and in the
// synopsis's (the file, then COUNT); wrong lists get a usage message, not the argument
// parser's; a compare that finds a difference (2007) says where, both values, how many.
TEST(CliFiles, W342_5_3_39_SaveInEitherOrderAndCompareSaysWhere) {
    ScratchDir dir("cli-files-compare");
    Finsd d({"--data-dir", (dir.path() / "data").string()});
    ASSERT_TRUE(d.started()) << d.result().err;
    ASSERT_EQ(
        fins(d, {"write", "D100", "0", "1", "2", "3", "4", "5", "6", "7", "8", "9"}).exit_code, 0);
    auto r = fins(d, {"files", "save", "D100", "10", "/D100.IOM"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "files save: 10 words\n");
    r = fins(d, {"files", "save", "D100", "/D101.IOM", "10"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Usage errors name the forms; nothing of the argument parser's wording.
    for (const std::vector<std::string>& bad :
         {std::vector<std::string>{"files", "save", "D100"},
          {"files", "save", "D100", "ten", "/X.IOM"},
          {"files", "save", "D100", "/X.IOM", "10", "extra"},
          {"files", "compare", "/D100.IOM", "D100", "many"}}) {
        r = fins(d, bad);
        EXPECT_EQ(r.exit_code, 2) << bad[2];
        EXPECT_NE(r.err.find("usage: files "), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("could not be converted"), std::string::npos) << r.err;
    }
    EXPECT_EQ(fins(d, {"files", "compare", "/D100.IOM", "D100", "10"}).exit_code, 0);
    ASSERT_EQ(fins(d, {"write", "D103", "99"}).exit_code, 0);
    ASSERT_EQ(fins(d, {"write", "D107", "0x77"}).exit_code, 0);
    r = fins(d, {"files", "compare", "/D100.IOM", "D100", "10"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("2007"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("2 of 10 words differ; the first is D103: file 0003, PLC 0063"),
              std::string::npos)
        << r.err;
    r = fins(d, {"--json", "files", "compare", "/D100.IOM", "D100", "12"});
    EXPECT_EQ(r.exit_code, 4);
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["error"]["end_code"], "2007");
    EXPECT_NE(j["error"]["context"].get<std::string>().find("the file holds 10 words, not 12"),
              std::string::npos)
        << r.out;
    // Parameter areas say the word of the area.
    ASSERT_EQ(fins(d, {"files", "save", "plc-setup", "/P.STD"}).exit_code, 0);
    ASSERT_EQ(fins(d, {"files", "compare", "/P.STD", "plc-setup"}).exit_code, 0);
    ASSERT_EQ(fins(d, {"files", "compare", "/D100.IOM", "plc-setup"}).exit_code, 4);
}
// DATA_DIR/card as a symlink (the card on another disk): finsd says at start that it
// follows it and files land behind it; a link that names no directory stops finsd at
// start (exit 3), naming it. Names from the network still never escape (plc tests).
TEST(CliFiles, FrameSerialFiles_4_1_SymlinkedCardIsFollowedAndLogged) {
    namespace fs = std::filesystem;
    ScratchDir dir("cli-files-link");
    fs::create_directories(dir.path() / "disk/sd");
    fs::create_directories(dir.path() / "data");
    fs::create_directory_symlink(dir.path() / "disk/sd", dir.path() / "data/card");
    {
        Finsd d({"--data-dir", (dir.path() / "data").string()});
        ASSERT_TRUE(d.started()) << d.result().err;
        const auto local = dir.write("a.txt", "hello");
        ASSERT_EQ(fins(d, {"files", "put", local, "/A.TXT"}).exit_code, 0);
        EXPECT_EQ(slurp(dir.path() / "disk/sd/A.TXT"), "hello");
        const auto stopped = d.stop();
        EXPECT_NE(stopped.err.find("card is a symlink to " + (dir.path() / "disk/sd").string() +
                                   ": followed"),
                  std::string::npos)
            << stopped.err;
    }
    fs::remove(dir.path() / "data/card");
    fs::create_directory_symlink(dir.path() / "disk/none", dir.path() / "data/card");
    Finsd broken({"--data-dir", (dir.path() / "data").string()});
    EXPECT_FALSE(broken.started());
    EXPECT_EQ(broken.result().exit_code, 3);
    EXPECT_NE(broken.result().err.find("card is a symlink to"), std::string::npos)
        << broken.result().err;
}

// W342 5-3-34 + the durability rule: 22 03 (0001) replacing a file while finsd
// is SIGKILLed leaves one whole version, never a mix, and never one older than the
// last acknowledged write.
TEST(CliFiles, W342_5_3_34_SigkillDuringReplaceLeavesOldOrNew) {
    ScratchDir dir("files-sigkill");
    const auto data = (dir.path() / "data").string();
    const auto name = *FileName::from("R.BIN");
    constexpr std::size_t requests = 200;
    std::vector<std::vector<std::uint8_t>> versions;
    for (std::size_t i = 0; i < requests; ++i) {
        const auto v = version(i);
        versions.emplace_back(v.begin(), v.end());
    }
    for (std::size_t round = 0; round < 3; ++round) {
        Finsd d({"--data-dir", data});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto client = d.client();
        ASSERT_TRUE(client);
        std::size_t acknowledged = 0;
        std::optional<std::size_t> last;
        const std::size_t kill_after = 20 + round * 40;
        // All in flight at once; the kill goes out from a completion while the rest are
        // queued or being written, at a point the test does not choose.
        for (std::size_t i = 0; i < requests; ++i)
            client->async_send(SingleFileWrite{disk_memory_card, 1, name, 0, versions[i], ""},
                               [&, i](Result<EmptyResponse> r) {
                                   if (!r) return;
                                   last = std::max(last.value_or(0), i);
                                   if (++acknowledged == kill_after) ::kill(d.pid(), SIGKILL);
                               });
        client->run();
        d.stop(SIGKILL);
        ASSERT_TRUE(last.has_value());
        const std::string on_disk = slurp(dir.path() / "data/card/R.BIN");
        ASSERT_EQ(on_disk.size(), 1900U) << "round " << round;
        const auto n = (static_cast<std::size_t>(static_cast<unsigned char>(on_disk[0])) << 8) |
                       static_cast<unsigned char>(on_disk[1]);
        ASSERT_LT(n, requests);
        EXPECT_EQ(on_disk, version(n)) << "round " << round << ": a mix of versions";
        EXPECT_GE(n, *last) << "round " << round << ": an acknowledged write was lost";
    }
    // A restarted finsd serves the file and leaves no temp file behind.
    Finsd d({"--data-dir", data});
    ASSERT_TRUE(d.started());
    auto client = d.client();
    const auto r = client->send(SingleFileRead{disk_memory_card, name, 0, 1900, ""});
    ASSERT_TRUE(r) << r.error().message();
    EXPECT_EQ(r->data.size(), 1900U);
    for (const auto& e : std::filesystem::directory_iterator(dir.path() / "data/card"))
        EXPECT_FALSE(e.path().filename().string().starts_with(".tmp-")) << e.path();
}

// `fins files cassette` on a CP1H (W342 5-3-43): save, type, verify, load, init, in
// PROGRAM mode only (2206 in RUN, exit 4); a difference is 2007 (exit 4); an unknown
// area is a usage error (exit 2); the cassette lives under the data directory.
TEST(CliFiles, W342_5_3_43_CassetteSaveVerifyLoadOnCp1h) {
    ScratchDir dir("cli-cassette");
    Finsd d({"--profile", "cp1h", "--data-dir", (dir.path() / "data").string()});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto r = fins(d, {"files", "cassette", "save"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("2206"), std::string::npos) << r.err;
    ASSERT_EQ(fins(d, {"stop"}).exit_code, 0);
    ASSERT_EQ(fins(d, {"write", "D100", "0x12AB"}).exit_code, 0);
    r = fins(d, {"files", "cassette", "save", "dm", "parameters"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "files cassette: done\n");
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "data/cassette/AUTOEXEC.IOM"));
    r = fins(d, {"files", "cassette", "type"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "parameters dm\n");
    r = fins(d, {"--json", "files", "cassette", "type"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["bits"], "0044");
    EXPECT_EQ(fins(d, {"files", "cassette", "verify", "dm"}).exit_code, 0);
    ASSERT_EQ(fins(d, {"write", "D100", "0"}).exit_code, 0);
    r = fins(d, {"files", "cassette", "verify"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("2007"), std::string::npos) << r.err;
    EXPECT_EQ(fins(d, {"files", "cassette", "load", "program"}).exit_code, 4);  // 2006
    ASSERT_EQ(fins(d, {"files", "cassette", "load"}).exit_code, 0);
    r = fins(d, {"read", "D100"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("4779"), std::string::npos) << r.out;  // 0x12AB
    EXPECT_EQ(fins(d, {"files", "cassette", "save", "nonsense"}).exit_code, 2);
    ASSERT_EQ(fins(d, {"files", "cassette", "init"}).exit_code, 0);
    r = fins(d, {"files", "cassette", "type"});
    EXPECT_EQ(r.out, "(empty)\n");
}

// Only the CP1H has a cassette: the default CJ2H answers 0401 (exit 4).
TEST(CliFiles, W342_5_3_43_CassetteUndefinedOnCj2h) {
    Finsd d({});
    ASSERT_TRUE(d.started()) << d.result().err;
    ASSERT_EQ(fins(d, {"stop"}).exit_code, 0);
    const auto r = fins(d, {"files", "cassette", "type"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("0401"), std::string::npos) << r.err;
}

// The cassette comes out and goes back at run time (finsd ctl cassette) and can be
// absent from the start ([files] cassette = false): without it 22 20 answers 2301 (W342
// 5-3-43 / 5-1-3 "file device missing"), exit 4; the CJ2H has no slot (ctl error).
TEST(CliFiles, W342_5_3_43_CassetteRemovedAndInsertedAtRunTime) {
    ScratchDir dir("cli-cassette-ctl");
    const auto socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--profile", "cp1h", "--mode", "program", "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto ctl = [&](std::string action) {
        return run({finsd_path, "ctl", "--socket", socket, "cassette", action});
    };
    ASSERT_EQ(fins(d, {"files", "cassette", "type"}).exit_code, 0);
    auto r = ctl("remove");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = fins(d, {"files", "cassette", "type"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("2301"), std::string::npos) << r.err;
    r = run({finsd_path, "ctl", "--socket", socket, "status"});
    EXPECT_NE(r.out.find("\"memory_cassette\":false"), std::string::npos) << r.out;
    ASSERT_EQ(ctl("insert").exit_code, 0);
    EXPECT_EQ(fins(d, {"files", "cassette", "type"}).exit_code, 0);

    const auto config =
        dir.write("no-cassette.toml", "profile = \"cp1h\"\n[files]\ncassette = false\n");
    Finsd without({"--config", config, "--mode", "program"});
    ASSERT_TRUE(without.started()) << without.result().err;
    r = fins(without, {"files", "cassette", "type"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("2301"), std::string::npos) << r.err;

    const auto socket2 = (dir.path() / "ctl2.sock").string();
    Finsd cj2h({"--control", socket2});
    ASSERT_TRUE(cj2h.started()) << cj2h.result().err;
    r = run({finsd_path, "ctl", "--socket", socket2, "cassette", "remove"});
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.out.find("no Memory Cassette slot"), std::string::npos) << r.out << r.err;
}

}  // namespace
}  // namespace fins::test
