// plc::FileMemory keeps a transfer's file open between 22 03 chunks (W342 5-3-34;
// FileMemory::OpenFile): appends reuse one descriptor, and every change that could make
// it stale (22 05 delete, 22 08 rename, 22 04 format, card removal, a replacing write,
// a host-side swap of the file or a symlink planted in its place) drops it, so a chunk
// never lands in a file that is no longer the one the name gives, and never outside the
// device directory. Bounded (max_open_files), closed when idle and at destruction.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "plc/file_memory/file_memory.hpp"
#include "plc/file_memory/file_memory_test_util.hpp"

namespace fins::plc {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

std::size_t open_descriptors() {
    return test::open_handles();
}

class OpenFilesTest : public ::testing::Test {
  protected:
    OpenFilesTest() : files(profile) {
        dir = test::make_temp_dir("fins-open-files");
        cleanup.dir = dir;
        EXPECT_TRUE(files.attach(dir / "root"));
    }

    EndCode write(std::string_view file, std::string_view content, FileWriteMode mode,
                  CivilSeconds now = 1'700'000'000, std::uint32_t position = 0) {
        const std::vector<std::uint8_t> data(content.begin(), content.end());
        return files.write({disk_memory_card, static_cast<std::uint16_t>(mode),
                            *FileName::from(file), position, data, ""},
                           now);
    }
    EndCode append(std::string_view file, std::string_view content,
                   CivilSeconds now = 1'700'000'000) {
        return write(file, content, FileWriteMode::append, now);
    }
    fs::path card() const { return dir / "root/card"; }

    Profile profile = cj2h();
    fs::path dir;
    test::RemoveAll cleanup;  // after `files` closed its directories (Windows removes none held)
    FileMemory files;
};

TEST_F(OpenFilesTest, W342_5_3_34_AppendsReuseOneDescriptor) {
    ASSERT_EQ(write("A.BIN", "0", FileWriteMode::create), EndCode::normal_completion);
    EXPECT_EQ(files.open_files(), 0U);  // a replacing write keeps nothing open
    for (const char* chunk : {"1", "2", "3"})
        ASSERT_EQ(append("A.BIN", chunk), EndCode::normal_completion);
    EXPECT_EQ(files.open_files(), 1U);
    EXPECT_EQ(slurp(card() / "A.BIN"), "0123");
    // 0003 at the file's end extends through the same descriptor.
    ASSERT_EQ(write("A.BIN", "4", FileWriteMode::overwrite, 1'700'000'000, 4),
              EndCode::normal_completion);
    EXPECT_EQ(files.open_files(), 1U);
    // 0003 inside the file replaces it (new inode): the descriptor goes, and later
    // appends reach the new file.
    ASSERT_EQ(write("A.BIN", "X", FileWriteMode::overwrite, 1'700'000'000, 0),
              EndCode::normal_completion);
    EXPECT_EQ(files.open_files(), 0U);
    ASSERT_EQ(append("A.BIN", "5"), EndCode::normal_completion);
    EXPECT_EQ(slurp(card() / "A.BIN"), "X12345");
    // The date is the CPU clock of the last chunk, given once rather than per chunk
    // (FileMemory::date_open_files): before 22 01 reads dates ...
    ASSERT_EQ(append("A.BIN", "6", 1'700'000'001), EndCode::normal_completion);
    ASSERT_TRUE(files.list({disk_memory_card, 0, 20, ""}));
    EXPECT_EQ(test::mtime_of(card() / "A.BIN"), 1'700'000'001);
    EXPECT_EQ(files.open_files(), 1U);  // still open for the next chunk
    // ... and when the descriptor is closed (here: the card comes out).
    ASSERT_EQ(append("A.BIN", "7", 1'700'000'009), EndCode::normal_completion);
    files.remove_card();
    EXPECT_EQ(files.open_files(), 0U);
    EXPECT_EQ(test::mtime_of(card() / "A.BIN"), 1'700'000'009);
}

// 22 02 chunks read through one kept descriptor too (issue 8 speed), and a file the
// host replaced under the same name is read afresh, never the old inode's bytes.
TEST_F(OpenFilesTest, W342_5_3_33_ReadsReuseOneDescriptorWhileTheNameHoldsTheFile) {
    ASSERT_EQ(write("R.BIN", "abcdef", FileWriteMode::create), EndCode::normal_completion);
    auto read = [&](std::uint32_t position, std::uint16_t length) {
        return files.read({disk_memory_card, *FileName::from("R.BIN"), position, length, ""});
    };
    auto first = read(0, 3);
    ASSERT_TRUE(first);
    EXPECT_EQ(std::string(first->data.begin(), first->data.end()), "abc");
    EXPECT_EQ(files.open_files(), 1U);
    const std::size_t descriptors = open_descriptors();
    auto second = read(3, 3);
    ASSERT_TRUE(second);
    EXPECT_EQ(std::string(second->data.begin(), second->data.end()), "def");
    EXPECT_TRUE(second->last);
    EXPECT_EQ(open_descriptors(), descriptors);  // no new open
    // Replaced on the host (new inode): the next read sees the new bytes.
    {
        std::ofstream out(card() / "R.BIN.new", std::ios::binary);
        out << "XYZ";
    }
    std::error_code replaced;
    fs::rename(card() / "R.BIN.new", card() / "R.BIN", replaced);
#ifdef _WIN32
    // Windows refuses to replace a file that is open (finsd holds it for the next chunk):
    // the swap does not happen, and the name still gives the file finsd reads.
    if (replaced) {
        fs::remove(card() / "R.BIN.new");
        { std::ofstream(card() / "R.BIN", std::ios::binary) << "XYZ"; }
    }
#else
    ASSERT_FALSE(replaced) << replaced.message();
#endif
    auto third = read(0, 3);
    ASSERT_TRUE(third);
    EXPECT_EQ(std::string(third->data.begin(), third->data.end()), "XYZ");
    EXPECT_EQ(third->file_size, 3U);
    // Deleted on the host: dropped from the cache, and 2006 on the next read.
    fs::remove(card() / "R.BIN");
#ifdef _WIN32
    // Windows (wine too) removes a file that is open once its last handle closes: the
    // name stays, with the bytes finsd read, until finsd lets go (here: the card comes out).
    files.remove_card();
    EXPECT_FALSE(fs::exists(card() / "R.BIN"));
#else
    EXPECT_FALSE(read(0, 1));
#endif
    EXPECT_EQ(files.open_files(), 0U);
}

TEST_F(OpenFilesTest, W342_5_3_36_DeleteRenameFormatAndCardRemovalDropIt) {
    ASSERT_EQ(write("A.BIN", "a", FileWriteMode::create), EndCode::normal_completion);
    ASSERT_EQ(append("A.BIN", "b"), EndCode::normal_completion);
    ASSERT_EQ(files.open_files(), 1U);
    ASSERT_TRUE(files.remove({disk_memory_card, {*FileName::from("A.BIN")}, ""}));
    EXPECT_EQ(files.open_files(), 0U);
    EXPECT_EQ(append("A.BIN", "c"), EndCode::write_file_missing);  // not the unlinked inode

    ASSERT_EQ(write("B.BIN", "b", FileWriteMode::create), EndCode::normal_completion);
    ASSERT_EQ(append("B.BIN", "b"), EndCode::normal_completion);
    ASSERT_EQ(
        files.rename({disk_memory_card, *FileName::from("B.BIN"), *FileName::from("C.BIN"), ""}),
        EndCode::normal_completion);
    EXPECT_EQ(files.open_files(), 0U);
    EXPECT_EQ(append("B.BIN", "x"), EndCode::write_file_missing);
    ASSERT_EQ(append("C.BIN", "c"), EndCode::normal_completion);
    EXPECT_EQ(slurp(card() / "C.BIN"), "bbc");

    EXPECT_EQ(files.open_files(), 1U);
    files.remove_card();
    EXPECT_EQ(files.open_files(), 0U);
    EXPECT_EQ(append("C.BIN", "x"), EndCode::file_device_missing);
    files.insert_card(1024);
    ASSERT_EQ(append("C.BIN", "d"), EndCode::normal_completion);
    EXPECT_EQ(files.open_files(), 1U);
    ASSERT_EQ(files.format(disk_memory_card, 0, 0), EndCode::normal_completion);
    EXPECT_EQ(files.open_files(), 0U);
    EXPECT_FALSE(fs::exists(card() / "C.BIN"));
}

// Behind finsd's back: the name given to another file, or to a symlink pointing out of
// the device: the next chunk follows the name's checks, never the stale descriptor.
TEST_F(OpenFilesTest, FrameSerialFiles_4_1_HostSwapsAreNotFollowed) {
    ASSERT_EQ(write("A.BIN", "a", FileWriteMode::create), EndCode::normal_completion);
    ASSERT_EQ(append("A.BIN", "b"), EndCode::normal_completion);
    fs::remove(card() / "A.BIN");
    { std::ofstream(card() / "A.BIN") << "new"; }
    ASSERT_EQ(append("A.BIN", "!"), EndCode::normal_completion);
    EXPECT_EQ(slurp(card() / "A.BIN"), "new!");

    const auto outside = dir / "outside.txt";
    { std::ofstream(outside) << "keep"; }
    fs::remove(card() / "A.BIN");
    if (!test::make_symlink(outside, card() / "A.BIN", false))
        GTEST_SKIP() << "the host makes no symlinks here";
    EXPECT_EQ(append("A.BIN", "evil"), EndCode::file_name_exists);
    EXPECT_EQ(slurp(outside), "keep");
    EXPECT_EQ(files.open_files(), 0U);
}

TEST_F(OpenFilesTest, W342_5_3_34_BoundedIdleClosedAndReleasedAtDestruction) {
    const auto before = open_descriptors();
    // Wine's GetProcessHandleCount says 0: there, only open_files() is checked.
    const bool counted = before != 0;
    {
        FileMemory other(profile);
        ASSERT_TRUE(other.attach(dir / "other"));
        const std::vector<std::uint8_t> zero{0};
        // The device directory stays open from the first request on: not counted.
        ASSERT_EQ(other.write({disk_memory_card, 1, *FileName::from("INIT"), 0, zero, ""}, 100),
                  EndCode::normal_completion);
        const auto baseline = open_descriptors();
        for (int i = 0; i < 6; ++i) {
            const std::string n = "F" + std::to_string(i) + ".BIN";
            const std::vector<std::uint8_t> one{1};
            ASSERT_EQ(other.write({disk_memory_card, 1, *FileName::from(n), 0, one, ""}, 100),
                      EndCode::normal_completion);
            ASSERT_EQ(other.write({disk_memory_card, 2, *FileName::from(n), 0, one, ""}, 100),
                      EndCode::normal_completion);
        }
        EXPECT_EQ(other.open_files(), FileMemory::max_open_files);
        if (counted) {
            EXPECT_EQ(open_descriptors(), baseline + 2 * FileMemory::max_open_files);
        }
        // Idle for longer than open_file_idle_seconds (CPU clock): closed at the next 22 03.
        const std::vector<std::uint8_t> one{1};
        ASSERT_EQ(other.write({disk_memory_card, 1, *FileName::from("G.BIN"), 0, one, ""},
                              100 + FileMemory::open_file_idle_seconds + 1),
                  EndCode::normal_completion);
        EXPECT_EQ(other.open_files(), 0U);
        if (counted) {
            EXPECT_EQ(open_descriptors(), baseline);
        }
        ASSERT_EQ(other.write({disk_memory_card, 2, *FileName::from("G.BIN"), 0, one, ""}, 200),
                  EndCode::normal_completion);
        EXPECT_EQ(other.open_files(), 1U);
    }
    if (counted) {
        EXPECT_EQ(open_descriptors(), before);
    }
}

}  // namespace
}  // namespace fins::plc
