// finsd and its state file (issue 6 items 5 and 6): a full file system is a clear
// exit 3 at every start, never a SIGBUS; a refused state file (empty, changed while
// stopped) stops finsd with exit 3 until --reset-state moves it aside; the [storage]
// keys and flags.
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "finsd/config.hpp"
#include "integration/support/finsd_process.hpp"
#include "plc/storage/storage_guard.hpp"

namespace fins::test {
namespace {

namespace fs = std::filesystem;

bool has(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// The byte offset of D`word` in a state file (storage_format.hpp: section table at 96,
// 64-byte entries: name 40, offset 8, size 8).
std::streamoff dm_offset(const fs::path& file, std::uint32_t word) {
    std::ifstream f(file, std::ios::binary);
    std::string header(4096, '\0');
    f.read(header.data(), 4096);
    for (std::size_t at = 96; at + 64 <= 3584; at += 64)
        if (header.compare(at, 6, std::string("io.dm\0", 6)) == 0) {
            std::uint64_t offset = 0;
            std::memcpy(&offset, header.data() + at + 40, sizeof offset);
            return static_cast<std::streamoff>(offset + 2 * word);
        }
    ADD_FAILURE() << "no io.dm section in " << file;
    return 0;
}

void write_d0(const Finsd& d, std::uint16_t value) {
    auto c = d.client(true);
    ASSERT_NE(c, nullptr);
    ASSERT_TRUE(c->write_words(addr("D0"), std::vector<std::uint16_t>{value}).has_value());
}

// Issue 6 item 5: the state file is reserved at creation, so a full file system is
// an error at start (exit 3, and again at the next start), never a SIGBUS on a write.
TEST(FinsdStateFile, FullFileSystemExits3AtEveryStart) {
    ScratchDir dir("statefs");
    const fs::path mnt = dir.path() / "small";
    fs::create_directories(mnt);
    if (::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=1m") != 0)
        GTEST_SKIP() << "cannot mount a 1 MiB tmpfs (" << std::strerror(errno)
                     << "): needs root or CAP_SYS_ADMIN";
    struct Unmount {
        fs::path dir;
        ~Unmount() { ::umount2(dir.c_str(), MNT_DETACH); }
    } unmount{mnt};
    for (int start = 0; start < 2; ++start) {
        Finsd d({"--profile", "cj2h", "--data-dir", (mnt / "data").string()});
        ASSERT_FALSE(d.started()) << "a 2.2 MB state file fit in 1 MiB";
        EXPECT_EQ(d.result().exit_code, 3) << d.result().err;
        EXPECT_TRUE(has(d.result().err, "cannot reserve")) << d.result().err;
        EXPECT_FALSE(fs::exists(mnt / "data" / "finsd.state"));
    }
    // A profile whose state fits (cj1m: 176 KB) starts on the same file system.
    Finsd small({"--profile", "cj1m", "--data-dir", (mnt / "data").string()});
    ASSERT_TRUE(small.started()) << small.result().err;
    write_d0(small, 0x1234);
    EXPECT_EQ(small.stop().exit_code, 0);
}

// Issue 6 item 6: a 0-byte state file stops finsd; only --reset-state starts it again,
// and that moves the old file aside instead of deleting it.
TEST(FinsdStateFile, EmptyStateFileNeedsResetStateWhichMovesItAside) {
    ScratchDir dir("statefile");
    const std::string data = (dir.path() / "data").string();
    const fs::path file = dir.path() / "data" / "finsd.state";
    {
        Finsd d({"--data-dir", data});
        ASSERT_TRUE(d.started()) << d.result().err;
        write_d0(d, 0x1234);
        EXPECT_EQ(d.stop().exit_code, 0);
    }
    {  // --reset-state leaves a usable file alone
        Finsd d({"--data-dir", data, "--reset-state"});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client(true);
        EXPECT_EQ(words_of(*c, "D0", 1), std::vector<std::uint16_t>{0x1234});
        EXPECT_EQ(d.stop().exit_code, 0);
    }
    fs::resize_file(file, 0);
    Finsd refused({"--data-dir", data});
    EXPECT_EQ(refused.result().exit_code, 3);
    EXPECT_TRUE(has(refused.result().err, "empty (0 bytes)")) << refused.result().err;
    EXPECT_TRUE(has(refused.result().err, "--reset-state")) << refused.result().err;
    EXPECT_EQ(fs::file_size(file), 0u);

    Finsd reset({"--data-dir", data, "--reset-state"});
    ASSERT_TRUE(reset.started()) << reset.result().err;
    auto c = reset.client(true);
    EXPECT_EQ(words_of(*c, "D0", 1), std::vector<std::uint16_t>{0});
    const auto stopped = reset.stop();
    EXPECT_EQ(stopped.exit_code, 0);
    EXPECT_TRUE(has(stopped.err, "moved it to")) << stopped.err;
    int aside = 0;
    for (const auto& e : fs::directory_iterator(dir.path() / "data"))
        if (e.path().filename().string().rfind("finsd.state.replaced-", 0) == 0) {
            ++aside;
            EXPECT_EQ(e.file_size(), 0u);
        }
    EXPECT_EQ(aside, 1);
    EXPECT_GT(fs::file_size(file), 4096u);
}

// Issue 6 item 6: a byte changed in a cleanly stopped file is detected at start.
TEST(FinsdStateFile, ByteChangedWhileStoppedIsRefused) {
    ScratchDir dir("statefile");
    const std::string data = (dir.path() / "data").string();
    const fs::path file = dir.path() / "data" / "finsd.state";
    {
        Finsd d({"--data-dir", data});
        ASSERT_TRUE(d.started()) << d.result().err;
        write_d0(d, 0x1234);
        EXPECT_EQ(d.stop(SIGTERM).exit_code, 0);
    }
    {
        std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(dm_offset(file, 0));
        f.put('\x35');  // D0 = 0x1235 (little-endian word)
    }
    Finsd refused({"--data-dir", data});
    EXPECT_EQ(refused.result().exit_code, 3);
    EXPECT_TRUE(has(refused.result().err, "fails its checksum")) << refused.result().err;
}

// Issue 18 item 5: `: > finsd.state` while finsd runs. The next access to a retained
// section ends finsd with exit 4 and one line naming the file (storage_guard.hpp),
// never a silent SIGBUS (exit 135); the emptied file is left as it is, and refused at
// the next start.
TEST(FinsdStateFile, TruncatedWhileRunningExits4WithALineNeverASigbus) {
    ScratchDir dir("statetrunc");
    const std::string data = (dir.path() / "data").string();
    const fs::path file = dir.path() / "data" / "finsd.state";
    Finsd d({"--data-dir", data});
    ASSERT_TRUE(d.started()) << d.result().err;
    write_d0(d, 0x1234);
    std::ofstream(file, std::ios::binary | std::ios::trunc).close();  // : > finsd.state
    {
        auto c = d.client(true);
        ASSERT_NE(c, nullptr);
        // D0 lives in the emptied file: no answer comes (finsd exits on this read).
        EXPECT_FALSE(c->read_words(addr("D0"), 1).has_value());
    }
    const auto ended = d.stop(0);  // signal 0: only waits
    EXPECT_EQ(ended.exit_code, plc::state_file_lost_exit_code) << ended.err;
    EXPECT_TRUE(has(ended.err, plc::state_file_lost_message(file.string()))) << ended.err;
    EXPECT_EQ(fs::file_size(file), 0u);
    Finsd refused({"--data-dir", data});
    EXPECT_EQ(refused.result().exit_code, 3);
    EXPECT_TRUE(has(refused.result().err, "empty (0 bytes)")) << refused.result().err;
}

// Truncated but never touched before SIGTERM: no seal is written over the lost data,
// and the exit says why (the same code and line).
TEST(FinsdStateFile, TruncatedThenStoppedExits4AndWritesNothing) {
    ScratchDir dir("statetrunc");
    const std::string data = (dir.path() / "data").string();
    const fs::path file = dir.path() / "data" / "finsd.state";
    Finsd d({"--data-dir", data});
    ASSERT_TRUE(d.started()) << d.result().err;
    std::ofstream(file, std::ios::binary | std::ios::trunc).close();
    const auto ended = d.stop(SIGTERM);
    EXPECT_EQ(ended.exit_code, plc::state_file_lost_exit_code) << ended.err;
    EXPECT_TRUE(has(ended.err, plc::state_file_lost_message(file.string()))) << ended.err;
    EXPECT_EQ(fs::file_size(file), 0u);
}

// Issue 27: a plant's CPU Unit is held to the same rule. Its state file truncated while
// finsd runs, with nothing touching it, is found by the check once a second over every
// CPU Unit's file: exit 4 and the guard's line naming that file, no seal written over
// it; the other CPU Unit's file is closed cleanly (a later start finds its checksums).
std::string two_cpu_plant(const ScratchDir& dir, const fs::path& data) {
    return dir.write("plant.toml", R"(
[[plc]]
name = "a"
data_dir = ")" + (data / "a").string() +
                                       R"("
  [[plc.ethernet]]
  network = 1
  bind = "127.0.0.1"
[[plc]]
name = "b"
data_dir = ")" + (data / "b").string() +
                                       R"("
  [[plc.ethernet]]
  network = 2
  bind = "127.0.0.1"
)");
}

TEST(FinsdStateFile, PlantUnitTruncatedWhileRunningExits4NamingItsFile) {
    ScratchDir dir("planttrunc");
    const fs::path data = dir.path() / "data";
    const fs::path lost = data / "b" / "finsd.state";
    const fs::path kept = data / "a" / "finsd.state";
    Finsd d({"--config", two_cpu_plant(dir, data)});
    ASSERT_TRUE(d.started()) << d.result().err;
    std::ofstream(lost, std::ios::binary | std::ios::trunc).close();  // : > b/finsd.state
    const auto ended = d.stop(0);  // signal 0: only waits (20 s at most)
    EXPECT_EQ(ended.exit_code, plc::state_file_lost_exit_code) << ended.err;
    EXPECT_TRUE(has(ended.err, plc::state_file_lost_message(lost.string()))) << ended.err;
    EXPECT_FALSE(has(ended.err, kept.string())) << ended.err;
    EXPECT_EQ(fs::file_size(lost), 0u);
    Finsd again({"--data-dir", kept.parent_path().string()});
    ASSERT_TRUE(again.started()) << again.result().err;
    const auto stopped = again.stop();
    EXPECT_EQ(stopped.exit_code, 0);
    EXPECT_FALSE(has(stopped.err, "not stopped cleanly")) << stopped.err;
}

// Truncated, then SIGTERM before anything looks: exit 4 too, as for a single node.
TEST(FinsdStateFile, PlantUnitTruncatedThenStoppedExits4) {
    ScratchDir dir("planttrunc");
    const fs::path data = dir.path() / "data";
    const fs::path lost = data / "a" / "finsd.state";
    Finsd d({"--config", two_cpu_plant(dir, data)});
    ASSERT_TRUE(d.started()) << d.result().err;
    std::ofstream(lost, std::ios::binary | std::ios::trunc).close();
    const auto ended = d.stop(SIGTERM);
    EXPECT_EQ(ended.exit_code, plc::state_file_lost_exit_code) << ended.err;
    EXPECT_TRUE(has(ended.err, plc::state_file_lost_message(lost.string()))) << ended.err;
    EXPECT_EQ(fs::file_size(lost), 0u);
}

TEST(FinsdStateFile, StorageKeysAndFlags) {
    using finsd::Settings;
    Settings s;
    EXPECT_EQ(s.durability, plc::Durability::process);
    ASSERT_TRUE(finsd::load_config_text("[storage]\ndurability = \"power\"\n", "t.toml", s));
    EXPECT_EQ(s.durability, plc::Durability::power);
    const auto bad = finsd::load_config_text("[storage]\ndurability = \"disk\"\n", "t.toml", s);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(), "t.toml:2:1: storage.durability: 'disk' is not process or power");
    const auto unknown = finsd::load_config_text("[storage]\nreset = true\n", "t.toml", s);
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.error(), "t.toml:2:1: storage.reset: unknown key");
    finsd::Overrides o;
    o.durability = "process";
    o.reset_state = true;
    ASSERT_TRUE(finsd::apply_overrides(o, s));
    EXPECT_EQ(s.durability, plc::Durability::process);
    EXPECT_TRUE(s.reset_state);
    Finsd flag({"--durability", "sometimes"});
    EXPECT_EQ(flag.result().exit_code, 2);
    s.durability = plc::Durability::power;
    const auto without_dir = finsd::validate(s);
    ASSERT_FALSE(without_dir);
    EXPECT_EQ(without_dir.error(),
              "storage.durability: \"power\" needs data_dir (without one nothing is kept)");
    s.data_dir = "/tmp/d";
    EXPECT_TRUE(finsd::validate(s));
}

}  // namespace
}  // namespace fins::test
