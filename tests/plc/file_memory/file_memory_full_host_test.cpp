// plc::FileMemory when the host file system fills up under a 22 03 (W342 5-3-34): the
// write answers 250F and the file stays exactly as the last acknowledged write left it,
// so the size 22 02 reports is the size a resuming client may trust. The full host is a
// 64 KiB tmpfs mounted for the test (needs CAP_SYS_ADMIN, else the test is skipped) and
// unmounted by it. Linux only: Windows has no tmpfs to mount (docs/windows.md).
#ifndef _WIN32
#include <gtest/gtest.h>

#include <sys/mount.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "plc/file_memory/file_memory.hpp"

namespace fins::plc {
namespace {

namespace fs = std::filesystem;

// A 64 KiB tmpfs on a fresh temporary directory, gone at the end of the test.
class SmallTmpfs {
  public:
    SmallTmpfs() {
        std::string pattern = (fs::temp_directory_path() / "fins-full-host-XXXXXX").string();
        if (::mkdtemp(pattern.data()) == nullptr) return;
        dir_ = pattern;
        mounted_ = ::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") == 0;
    }
    ~SmallTmpfs() {
        if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
        if (!dir_.empty()) ::rmdir(dir_.c_str());
    }
    SmallTmpfs(const SmallTmpfs&) = delete;
    SmallTmpfs& operator=(const SmallTmpfs&) = delete;
    [[nodiscard]] bool mounted() const noexcept { return mounted_; }
    [[nodiscard]] const fs::path& dir() const noexcept { return dir_; }

  private:
    fs::path dir_;
    bool mounted_ = false;
};

std::vector<std::uint8_t> pattern_bytes(std::size_t n) {
    std::vector<std::uint8_t> out(n);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = static_cast<std::uint8_t>(i * 7 + i / 251);
    return out;
}

TEST(FileMemoryFullHost, W342_5_3_34_RefusedExtendLeavesTheFileAsAcknowledged) {
    SmallTmpfs tmpfs;
    if (!tmpfs.mounted()) GTEST_SKIP() << "mounting a tmpfs needs CAP_SYS_ADMIN";
    Profile profile = cj2h();
    FileMemory files(profile);
    files.insert_card(1024);  // 1 MB: the card's quota is not what stops the writes
    ASSERT_TRUE(files.attach(tmpfs.dir() / "root"));
    // 1,500-byte chunks cross the tmpfs's 4 KiB pages, so the last one fits part way.
    const auto data = pattern_bytes(200 * 1500);
    const auto name = *FileName::from("A.BIN");
    ASSERT_EQ(files.write({disk_memory_card, 0, name, 0, Bytes(data).first(1500), ""}, 0),
              EndCode::normal_completion);
    std::size_t acknowledged = 1500;
    EndCode refused = EndCode::normal_completion;
    for (std::size_t i = 1; i < 200 && refused == EndCode::normal_completion; ++i) {
        // Both extending modes: 0002 append and 0003 at the file's end.
        const bool append = i % 2 == 0;
        const auto code = files.write({disk_memory_card, static_cast<std::uint16_t>(append ? 2 : 3),
                                       name, append ? 0U : static_cast<std::uint32_t>(acknowledged),
                                       Bytes(data).subspan(acknowledged, 1500), ""},
                                      0);
        if (code == EndCode::normal_completion)
            acknowledged += 1500;
        else
            refused = code;
    }
    ASSERT_EQ(refused, EndCode::memory_error) << "the 64 KiB tmpfs never filled up";
    EXPECT_EQ(fs::file_size(tmpfs.dir() / "root/card/A.BIN"), acknowledged);
    const auto size = files.read({disk_memory_card, name, 0, 0, ""});
    ASSERT_TRUE(size);
    EXPECT_EQ(size->file_size, acknowledged);
    std::ifstream in(tmpfs.dir() / "root/card/A.BIN", std::ios::binary);
    const std::vector<std::uint8_t> stored((std::istreambuf_iterator<char>(in)), {});
    EXPECT_TRUE(stored ==
                std::vector<std::uint8_t>(
                    data.begin(), data.begin() + static_cast<std::ptrdiff_t>(acknowledged)));
    // Acknowledged bytes are counted, refused ones are not.
    const auto list = files.list({disk_memory_card, 0, 0, ""});
    ASSERT_TRUE(list);
    EXPECT_EQ(list->disk.total_capacity - list->disk.free_capacity, acknowledged);
}

}  // namespace
}  // namespace fins::plc
#endif
