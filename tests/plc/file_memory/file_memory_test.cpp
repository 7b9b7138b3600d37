// plc::FileMemory (W342 5-3-32 .. 5-3-42, frames-serial-files 4): name and path rules
// before any host access, no escape from the device directory (.., absolute paths,
// symlinks, NUL bytes, device names), capacity quotas, atomic replacement.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "plc/file_memory/file_memory.hpp"
#include "plc/file_memory/file_memory_test_util.hpp"

namespace fins::plc {
namespace {

namespace fs = std::filesystem;

FileName name(std::string_view text) {
    return *FileName::from(text);
}

std::vector<std::uint8_t> bytes(std::string_view s) {
    return {s.begin(), s.end()};
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

// Everything a test may create: <sandbox>/root holds the devices; the rest of the
// sandbox is "outside" and must stay untouched.
struct Sandbox {
    Sandbox() {
        dir = test::make_temp_dir("fins-files-test");
        fs::create_directories(dir / "root");
    }
    ~Sandbox() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    // Entries outside the root.
    [[nodiscard]] std::size_t outside() const {
        std::size_t n = 0;
        for (const auto& e : fs::directory_iterator(dir))
            if (e.path().filename() != "root") ++n;
        return n;
    }
    fs::path dir;
};

class FileMemoryTest : public ::testing::Test {
  protected:
    FileMemoryTest() : files(profile) { EXPECT_TRUE(files.attach(box.dir / "root")); }
    EndCode put(std::string_view file, std::string_view content, std::string dir = "",
                FileWriteMode mode = FileWriteMode::create_or_replace) {
        const auto data = bytes(content);
        return files.write({disk_memory_card, static_cast<std::uint16_t>(mode), name(file), 0, data,
                            std::move(dir)},
                           1'700'000'000);
    }
    Profile profile = cj2h();
    Sandbox box;
    FileMemory files;
};

TEST(FileNames, FrameSerialFiles_4_1_NameRules) {
    EXPECT_EQ(FileMemory::canonical_name("autoexec.iom"), "AUTOEXEC.IOM");
    EXPECT_EQ(FileMemory::canonical_name("A!&$#'{}"), "A!&$#'{}");
    EXPECT_EQ(FileMemory::canonical_name("X-^()_~1.Z"), "X-^()_~1.Z");
    for (const char* bad :
         {"",       "..",  ".",       "~~A",  "A B",    "A*",    "A?",    "A/B",
          "A\\B",   "A:B", "A;B",     "A+B",  "A=B",    "A,B",   "NAME.", "TOOLONGNAME",
          "A.LONG", "CON", "nul.txt", "COM1", "LPT9.X", "A.B.C", "\xE5X"})
        EXPECT_FALSE(FileMemory::canonical_name(std::string_view(bad))) << bad;
    EXPECT_FALSE(FileMemory::canonical_name(std::string_view("A\0B", 3)));
    // Wire names: first byte 00 or E5, bytes after the padding, "." without extension.
    FileName n = name("A.B");
    EXPECT_EQ(FileMemory::canonical_name(n), "A.B");
    n.bytes[0] = 0x00;
    EXPECT_FALSE(FileMemory::canonical_name(n));
    n = name("A");
    n.bytes[5] = 'X';
    EXPECT_FALSE(FileMemory::canonical_name(n));
    n = name("A");
    n.bytes[8] = '.';
    EXPECT_FALSE(FileMemory::canonical_name(n));
}

TEST_F(FileMemoryTest, W342_5_3_34_WriteModes) {
    EXPECT_EQ(put("A.TXT", "one", "", FileWriteMode::create), EndCode::normal_completion);
    EXPECT_EQ(put("A.TXT", "two", "", FileWriteMode::create), EndCode::file_name_exists);
    EXPECT_EQ(put("a.txt", "three"), EndCode::normal_completion);  // case-insensitive
    EXPECT_EQ(slurp(box.dir / "root/card/A.TXT"), "three");
    EXPECT_EQ(put("A.TXT", "+", "", FileWriteMode::append), EndCode::normal_completion);
    EXPECT_EQ(slurp(box.dir / "root/card/A.TXT"), "three+");
    EXPECT_EQ(put("B.TXT", "x", "", FileWriteMode::append), EndCode::write_file_missing);
    EXPECT_EQ(put("B.TXT", "x", "", FileWriteMode::overwrite), EndCode::write_file_missing);
    const auto patch = bytes("HR");
    EXPECT_EQ(files.write({disk_memory_card, 3, name("A.TXT"), 1, patch, ""}, 0),
              EndCode::normal_completion);
    EXPECT_EQ(slurp(box.dir / "root/card/A.TXT"), "tHRee+");
    EXPECT_EQ(files.write({disk_memory_card, 3, name("A.TXT"), 7, patch, ""}, 0),
              EndCode::address_range_error);  // past the end
    EXPECT_EQ(files.write({disk_memory_card, 0, name("C.TXT"), 4, patch, ""}, 0),
              EndCode::parameter_error);  // a new file starts at 0
    EXPECT_EQ(files.write({disk_memory_card, 4, name("C.TXT"), 0, patch, ""}, 0),
              EndCode::parameter_error);  // no mode 0004
    EXPECT_EQ(put("C.TXT", "x", "\\NODIR"), EndCode::write_file_missing);
}

TEST_F(FileMemoryTest, W342_5_3_34_DatedWithTheCpuClock) {
    ASSERT_EQ(put("A.TXT", "x"), EndCode::normal_completion);
    const auto list = files.list({disk_memory_card, 0, 20, ""});
    ASSERT_TRUE(list);
    ASSERT_EQ(list->files.size(), 2U);  // the volume label, then the file
    // 1,700,000,000 = 2023-11-14 22:13:20
    EXPECT_EQ(list->files[1].date, pack_file_date(2023, 11, 14, 22, 13, 20));
    EXPECT_EQ(list->files[1].size, 1U);
    EXPECT_EQ(list->files[1].attribute, attribute_archive);
}

TEST_F(FileMemoryTest, HostileNamesNeverLeaveTheDevice) {
    // A symlink planted in the card pointing outside: neither followed nor listed (where
    // the host lets a test make one: not under wine, where windows_file_memory.sh plants
    // them from the Linux side).
    fs::create_directories(box.dir / "root/card");
    fs::create_directory(box.dir / "secret");
    { std::ofstream(box.dir / "secret/KEY.TXT") << "secret"; }
    const bool links =
        test::make_symlink(box.dir / "secret", box.dir / "root/card/LINK", true) &&
        test::make_symlink(box.dir / "secret/KEY.TXT", box.dir / "root/card/KEY.TXT", false);
    const auto before = box.outside();
    if (links) {
        EXPECT_FALSE(files.read({disk_memory_card, name("KEY.TXT"), 0, 10, ""}));
        EXPECT_EQ(files.read({disk_memory_card, name("KEY.TXT"), 0, 10, "\\LINK"}).error(),
                  EndCode::read_file_missing);
        EXPECT_EQ(put("NEW.TXT", "x", "\\LINK"), EndCode::write_file_missing);
        EXPECT_EQ(put("KEY.TXT", "x", "", FileWriteMode::append), EndCode::file_name_exists);
        EXPECT_EQ(put("KEY.TXT", "x"), EndCode::file_name_exists);
    }
    for (const char* path :
         {"\\..", "..", "\\A\\..\\..", "/etc", "\\A\\", "C:\\A", "\\A\\\\B", "\\A/B", "\\CON",
          "\\A\\B\\C\\D\\E", "\\A:B", "\\A.", "\\A B", "\\LPT0", "\\CONIN$"}) {
        EXPECT_EQ(put("X.TXT", "x", path), EndCode::parameter_error) << path;
        EXPECT_EQ(files.list({disk_memory_card, 0, 1, path}).error(), EndCode::parameter_error)
            << path;
    }
    // Names Windows treats specially: streams, trailing dots, spaces, device names (as
    // the 12 wire bytes: base padded to 8, '.', extension padded to 3).
    const auto raw = [](std::string_view base, std::string_view ext, bool dot) {
        FileName n;
        n.bytes.fill(0x20);
        std::copy(base.begin(), base.end(), n.bytes.begin());
        if (dot) n.bytes[8] = '.';
        std::copy(ext.begin(), ext.end(), n.bytes.begin() + 9);
        return n;
    };
    const auto data = bytes("x");
    for (const auto& file :
         {raw("A:B", "", false), raw("A", "T:S", true), raw("A", "", true), raw("A B", "", false),
          raw("A", "T X", true), raw("CON", "", false), raw("NUL", "TXT", true),
          raw("COM0", "X", true), raw("CONOUT$", "", false), raw("LPT9", "", false)})
        EXPECT_EQ(files.write({disk_memory_card, 1, file, 0, data, ""}, 0),
                  EndCode::parameter_error)
            << std::string(file.bytes.begin(), file.bytes.end());
    EXPECT_EQ(put("X.TXT", "x", std::string("\\A\0B", 4)), EndCode::parameter_error);
    EXPECT_EQ(put("X.TXT", "x", "\\" + std::string(65, 'A')), EndCode::parameter_error);
    const auto list = files.list({disk_memory_card, 0, 20, ""});
    ASSERT_TRUE(list);
    ASSERT_EQ(list->files.size(), 1U);  // the symlinks are invisible: the volume label only
    EXPECT_EQ(list->files[0].attribute, attribute_volume);
    EXPECT_EQ(slurp(box.dir / "secret/KEY.TXT"), "secret");
    EXPECT_EQ(box.outside(), before);
    EXPECT_EQ(fs::directory_iterator(box.dir / "secret")->path().filename(), "KEY.TXT");
}

TEST_F(FileMemoryTest, W342_5_3_34_FullCardAnswers1104AndKeepsTheFile) {
    files.insert_card(1);  // 1 KB
    ASSERT_EQ(put("A.BIN", std::string(1000, 'a')), EndCode::normal_completion);
    EXPECT_EQ(put("B.BIN", std::string(100, 'b')), EndCode::address_range_exceeded);
    EXPECT_EQ(put("A.BIN", std::string(1100, 'c')), EndCode::address_range_exceeded);
    EXPECT_EQ(put("A.BIN", std::string(30, 'd'), "", FileWriteMode::append),
              EndCode::address_range_exceeded);
    EXPECT_EQ(slurp(box.dir / "root/card/A.BIN"), std::string(1000, 'a'));
    EXPECT_FALSE(fs::exists(box.dir / "root/card/B.BIN"));
    const auto list = files.list({disk_memory_card, 0, 0, ""});
    ASSERT_TRUE(list);
    EXPECT_EQ(list->disk.total_capacity, 1024U);
    EXPECT_EQ(list->disk.free_capacity, 24U);
}

TEST_F(FileMemoryTest, W342_5_3_34_ReplaceLeavesNoTempFiles) {
    ASSERT_EQ(put("A.TXT", "old"), EndCode::normal_completion);
    ASSERT_EQ(put("A.TXT", "new"), EndCode::normal_completion);
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(box.dir / "root/card"))
        if (e.path().filename() != ".volume") ++n;
    EXPECT_EQ(n, 1U);
    // A temp file a killed finsd left behind is removed at the next attach.
    { std::ofstream(box.dir / "root/card/.tmp-1-1") << "half"; }
    FileMemory again(profile);
    ASSERT_TRUE(again.attach(box.dir / "root"));
    EXPECT_FALSE(fs::exists(box.dir / "root/card/.tmp-1-1"));
}

TEST_F(FileMemoryTest, W342_5_3_32_ListingAcrossRequests) {
    for (int i = 0; i < 25; ++i)
        ASSERT_EQ(put("F" + std::to_string(i), "x"), EndCode::normal_completion);
    const auto first = files.list({disk_memory_card, 0, 20, ""});
    ASSERT_TRUE(first);
    EXPECT_EQ(first->disk.total_files, 26);  // with the volume label (5-3-32)
    EXPECT_EQ(first->files.size(), 20U);
    EXPECT_FALSE(first->last);
    const auto rest = files.list({disk_memory_card, 20, 20, ""});
    ASSERT_TRUE(rest);
    EXPECT_EQ(rest->files.size(), 6U);
    EXPECT_TRUE(rest->last);
    EXPECT_EQ(files.list({disk_memory_card, 0, 21, ""}).error(), EndCode::parameter_error);
    // A sub-directory lists "." and ".." first.
    ASSERT_EQ(files.directory({disk_memory_card, 0, name("SUB"), ""}, 0),
              EndCode::normal_completion);
    const auto sub = files.list({disk_memory_card, 0, 20, "\\SUB"});
    ASSERT_TRUE(sub);
    ASSERT_EQ(sub->files.size(), 2U);
    EXPECT_EQ(sub->files[0].name.text(), ".");
    EXPECT_EQ(sub->files[1].attribute, attribute_directory);
}

TEST_F(FileMemoryTest, W342_5_3_32_RootCountsTheVolumeLabelAsAFile) {
    ASSERT_EQ(files.format(disk_memory_card, 0, 1'700'000'000), EndCode::normal_completion);
    ASSERT_EQ(put("A.TXT", "abc"), EndCode::normal_completion);
    ASSERT_EQ(files.directory({disk_memory_card, 0, name("SUB"), ""}, 0),
              EndCode::normal_completion);
    const auto root = files.list({disk_memory_card, 0, 20, ""});
    ASSERT_TRUE(root);
    // "Volume labels ... are all counted as files. (The root directory can contain a
    // volume label, but not a current directory or parent directory mark.)"
    EXPECT_EQ(root->disk.total_files, 3);
    ASSERT_EQ(root->files.size(), 3U);
    const FileEntry& label = root->files[0];
    EXPECT_EQ(label.name, root->disk.volume_label);
    EXPECT_EQ(label.name.text(), "MEMCARD");
    EXPECT_EQ(label.attribute, attribute_volume);
    EXPECT_EQ(label.size, 0U);
    EXPECT_EQ(label.date, root->disk.date);
    EXPECT_EQ(label.date, pack_file_date(2023, 11, 14, 22, 13, 20));
    EXPECT_EQ(root->files[1].name.text(), "A.TXT");
    EXPECT_EQ(root->files[2].name.text(), "SUB");
    EXPECT_TRUE(root->last);
    // Positions count the label: the file is entry 1.
    const auto second = files.list({disk_memory_card, 1, 1, ""});
    ASSERT_TRUE(second);
    ASSERT_EQ(second->files.size(), 1U);
    EXPECT_EQ(second->files[0].name.text(), "A.TXT");
    // A sub-directory has no label: ".", "..", then its entries.
    const auto sub = files.list({disk_memory_card, 0, 20, "\\SUB"});
    ASSERT_TRUE(sub);
    EXPECT_EQ(sub->disk.total_files, 2);
    for (const auto& e : sub->files)
        EXPECT_EQ(e.attribute & attribute_volume, 0);
    // EM file memory's root has its own label.
    files.set_em_file_bank(0x10);
    const auto em = files.list({disk_em_file, 0, 20, ""});
    ASSERT_TRUE(em);
    EXPECT_EQ(em->disk.total_files, 1);
    ASSERT_EQ(em->files.size(), 1U);
    EXPECT_EQ(em->files[0].name.text(), "EMFILE");
    EXPECT_EQ(em->files[0].attribute, attribute_volume);
}

TEST_F(FileMemoryTest, W342_5_3_42_DirectoryRules) {
    EXPECT_EQ(files.directory({disk_memory_card, 0, name("A"), ""}, 0), EndCode::normal_completion);
    EXPECT_EQ(files.directory({disk_memory_card, 0, name("A"), ""}, 0), EndCode::file_name_exists);
    EXPECT_EQ(files.directory({disk_memory_card, 0, name("B"), "\\A"}, 0),
              EndCode::normal_completion);
    EXPECT_EQ(files.directory({disk_memory_card, 0, name("C"), "\\A\\B"}, 0),
              EndCode::normal_completion);
    EXPECT_EQ(files.directory({disk_memory_card, 0, name("D"), "\\A\\B\\C"}, 0),
              EndCode::normal_completion);
    // 5 levels counting the root.
    EXPECT_EQ(files.directory({disk_memory_card, 0, name("E"), "\\A\\B\\C\\D"}, 0),
              EndCode::cannot_register);
    EXPECT_EQ(files.directory({disk_memory_card, 1, name("A"), ""}, 0), EndCode::cannot_change);
    EXPECT_EQ(files.directory({disk_memory_card, 1, name("Z"), ""}, 0),
              EndCode::write_file_missing);
    EXPECT_EQ(files.directory({disk_memory_card, 2, name("Z"), ""}, 0), EndCode::parameter_error);
}

TEST_F(FileMemoryTest, W342_5_3_35_DevicesMissingAndFormat) {
    // EM file memory is off in the default profile; unknown disks are a parameter error.
    EXPECT_EQ(files.list({disk_em_file, 0, 0, ""}).error(), EndCode::file_device_missing);
    EXPECT_EQ(files.list({0x8002, 0, 0, ""}).error(), EndCode::parameter_error);
    files.set_em_file_bank(0x10);
    EXPECT_EQ(files.em_non_file_banks(), 0x10);
    const auto em = files.list({disk_em_file, 0, 0, ""});
    ASSERT_TRUE(em);
    EXPECT_EQ(em->disk.total_capacity, 9U * em_bank_bytes);  // banks 10-18 hex
    // 5-3-35 note: 1101 when the current EM bank is a file bank (not EM0).
    EXPECT_EQ(files.format(disk_em_file, 0x11, 0), EndCode::area_classification_missing);
    EXPECT_EQ(files.format(disk_em_file, 0x00, 0), EndCode::normal_completion);
    ASSERT_EQ(put("A.TXT", "x"), EndCode::normal_completion);
    EXPECT_EQ(files.format(disk_memory_card, 0, 1'700'000'000), EndCode::normal_completion);
    const auto after = files.list({disk_memory_card, 0, 20, ""});
    ASSERT_TRUE(after);
    ASSERT_EQ(after->files.size(), 1U);  // the volume label, dated by the format
    EXPECT_EQ(after->files[0].date, pack_file_date(2023, 11, 14, 22, 13, 20));
    EXPECT_EQ(after->disk.date, pack_file_date(2023, 11, 14, 22, 13, 20));
    files.remove_card();
    EXPECT_EQ(put("A.TXT", "x"), EndCode::file_device_missing);
}

// frames-serial-files 4 "a hostile path never escapes" is about names from the network;
// <root>/card itself comes from whoever owns the data directory: a symlink there (the card
// on another disk) is followed at attach() and reported; a broken one fails attach().
TEST(FileMemoryDeviceLinks, FrameSerialFiles_4_1_CardSymlinkIsFollowedAndReported) {
    Sandbox box;
    Profile profile = cj2h();
    fs::create_directories(box.dir / "disk/cardstore");
    { std::ofstream(box.dir / "disk/cardstore/.tmp-9-9") << "half"; }
    if (!test::make_symlink(box.dir / "disk/cardstore", box.dir / "root/card", true))
        GTEST_SKIP() << "the host makes no symlinks here";
    FileMemory files(profile);
    ASSERT_TRUE(files.attach(box.dir / "root"));
    ASSERT_EQ(files.device_links().size(), 1U);
    EXPECT_EQ(files.device_links()[0].device, "card");
    EXPECT_EQ(files.device_links()[0].target, box.dir / "disk/cardstore");
    EXPECT_FALSE(files.device_links()[0].error);
    EXPECT_FALSE(fs::exists(box.dir / "disk/cardstore/.tmp-9-9"));  // cleaned like any card
    const auto data = bytes("on the other disk");
    EXPECT_EQ(files.write({disk_memory_card, 0, name("A.TXT"), 0, data, ""}, 0),
              EndCode::normal_completion);
    EXPECT_EQ(slurp(box.dir / "disk/cardstore/A.TXT"), "on the other disk");
    const auto list = files.list({disk_memory_card, 0, 20, ""});
    ASSERT_TRUE(list);
    EXPECT_EQ(list->disk.total_files, 2);  // the volume label and A.TXT
    // Below the followed directory, symlinks are still neither followed nor listed.
    fs::create_directory(box.dir / "secret");
    fs::create_directory_symlink(box.dir / "secret", box.dir / "disk/cardstore/LINK");
    EXPECT_EQ(files.write({disk_memory_card, 0, name("X.TXT"), 0, data, "\\LINK"}, 0),
              EndCode::write_file_missing);
    EXPECT_TRUE(fs::is_empty(box.dir / "secret"));

    // Dangling, or naming a file: refused at attach, the link named.
    fs::remove(box.dir / "root/card");
    fs::create_directory_symlink(box.dir / "disk/none", box.dir / "root/card");
    FileMemory dangling(profile);
    EXPECT_FALSE(dangling.attach(box.dir / "root"));
    ASSERT_EQ(dangling.device_links().size(), 1U);
    EXPECT_TRUE(dangling.device_links()[0].error);
    fs::remove(box.dir / "root/card");
    { std::ofstream(box.dir / "disk/file") << "x"; }
    fs::create_symlink(box.dir / "disk/file", box.dir / "root/card");
    FileMemory to_file(profile);
    const auto r = to_file.attach(box.dir / "root");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), std::errc::not_a_directory);
    // Without links there is nothing to report.
    fs::remove(box.dir / "root/card");
    FileMemory plain(profile);
    ASSERT_TRUE(plain.attach(box.dir / "root"));
    EXPECT_TRUE(plain.device_links().empty());
}

}  // namespace
}  // namespace fins::plc
