// The state file's integrity and space (issue 6 items 5 and 6): checksums checked after
// a clean stop, what is checked after a SIGKILL, refusal of empty and incomplete files,
// moving a refused file aside, a full file system or a file size limit refused at start
// (never a SIGBUS), and the durability setting.
// Linux only: the checks after a kill need fork, mount and setrlimit (docs/windows.md;
// finsd.exe's state file is tested end to end by tests/scripts/windows_finsd.sh).
#ifndef _WIN32
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "plc/storage/crc32c.hpp"
#include "plc/storage/storage.hpp"
#include "plc/storage/storage_guard.hpp"

namespace fins::plc::test {
namespace {

namespace fs = std::filesystem;

constexpr auto R = Retention::retained;
constexpr std::streamoff complete_at = 12;
constexpr std::streamoff seal_at = 3584;
constexpr std::streamoff first_section_at = 4096;

class StateFile : public ::testing::Test {
  protected:
    void SetUp() override {
        static std::atomic<int> n{0};
        dir_ = fs::temp_directory_path() /
               ("finskit-state-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
        fs::remove_all(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    [[nodiscard]] fs::path state() const { return dir_ / "finsd.state"; }

    // A state file with "a" (100 words, a[99] = A099) and "b" (10 words), closed
    // cleanly (the destructor) unless `killed`: then the process that made it ends
    // without closing, as after SIGKILL.
    void create(bool killed = false) {
        if (killed) {
            const pid_t pid = ::fork();
            if (pid == 0) {
                auto s = Storage::open(dir_, "p1");
                if (!s) ::_exit(2);
                (*s)->array<std::uint16_t>("a", 100, R)[99] = 0xA099;
                (*s)->array<std::uint16_t>("b", 10, R);
                ::_exit((*s)->seal() ? 0 : 3);
            }
            int status = 0;
            ::waitpid(pid, &status, 0);
            ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
            return;
        }
        auto s = Storage::open(dir_, "p1");
        ASSERT_TRUE(s) << s.error().message();
        auto a = (*s)->array<std::uint16_t>("a", 100, R);
        (*s)->array<std::uint16_t>("b", 10, R);
        ASSERT_TRUE((*s)->seal());
        a[99] = 0xA099;
    }
    void poke(std::streamoff at, const void* bytes, std::size_t n) {
        std::fstream f(state(), std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(at);
        f.write(static_cast<const char*>(bytes), static_cast<std::streamsize>(n));
    }
    std::string contents() const {
        std::ifstream f(state(), std::ios::binary);
        return {std::istreambuf_iterator<char>(f), {}};
    }
    static std::string message(const Result<std::unique_ptr<Storage>>& r) {
        return r ? std::string("opened") : r.error().message();
    }
    // Opens with the layout of create(); the values of "a".
    std::vector<std::uint16_t> reopen_a(bool* verified = nullptr) {
        auto s = Storage::open(dir_, "p1");
        EXPECT_TRUE(s) << message(s);
        if (!s) return {};
        auto a = (*s)->array<std::uint16_t>("a", 100, R);
        (*s)->array<std::uint16_t>("b", 10, R);
        EXPECT_TRUE((*s)->seal());
        if (verified != nullptr) *verified = (*s)->checksums_verified();
        return {a.begin(), a.end()};
    }

    fs::path dir_;
};

TEST(Crc32c, CheckValueOfTheCastagnoliPolynomial) {
    const std::string check = "123456789";
    EXPECT_EQ(crc32c(std::as_bytes(std::span(check.data(), check.size()))), 0xE3069283U);
    // In pieces (the header checksums are computed around their own field).
    const auto bytes = std::as_bytes(std::span(check.data(), check.size()));
    EXPECT_EQ(crc32c(bytes.subspan(5), crc32c(bytes.first(5))), 0xE3069283U);
    EXPECT_EQ(crc32c({}), 0U);
}

TEST_F(StateFile, CleanStopVerifiesEverySectionAtTheNextStart) {
    create();
    bool verified = false;
    EXPECT_EQ(reopen_a(&verified)[99], 0xA099);
    EXPECT_TRUE(verified);
}

// Issue 6 item 6: a byte flipped while finsd was stopped is no longer served.
TEST_F(StateFile, ByteChangedInACleanlyStoppedFileIsRefusedAndKept) {
    create();
    const char flipped = '\x5A';
    poke(first_section_at + 198, &flipped, 1);  // a[99]'s low byte
    const std::string before = contents();
    const auto r = Storage::open(dir_, "p1");
    ASSERT_FALSE(r);
    EXPECT_NE(message(r).find("fails its checksum"), std::string::npos) << message(r);
    EXPECT_TRUE(Storage::is_refusal(r.error()));
    EXPECT_EQ(contents(), before);  // never written to
}

// Choice: after a SIGKILL (or a crash, or power loss) the sections' checksums are
// stale by design (they are written only at a clean stop), so only the header and the
// section table are checked, and checksums_verified() says so (finsd logs a warning).
TEST_F(StateFile, AfterAKillOnlyTheHeaderAndSectionTableAreChecked) {
    create(/*killed=*/true);
    bool verified = true;
    EXPECT_EQ(reopen_a(&verified)[99], 0xA099);
    EXPECT_FALSE(verified);
    // The limit, as documented: data changed after a kill is served, since nothing
    // tells it apart from an acknowledged write. The structure still is checked.
    create(/*killed=*/true);
    const char changed = '\x5A';
    poke(first_section_at + 198, &changed, 1);
    EXPECT_EQ(reopen_a()[99], 0xA05A);
    create(/*killed=*/true);
    const std::uint64_t bad_size = 1;
    poke(96 + 48, &bad_size, sizeof bad_size);  // first entry's size
    EXPECT_NE(message(Storage::open(dir_, "p1")).find("damaged"), std::string::npos);
}

TEST_F(StateFile, ZeroedCompleteFlagIsRefused) {
    create();
    const std::uint32_t zero = 0;
    poke(complete_at, &zero, sizeof zero);
    const auto r = Storage::open(dir_, "p1");
    EXPECT_NE(message(r).find("\"complete\" flag"), std::string::npos) << message(r);
    EXPECT_TRUE(!r && Storage::is_refusal(r.error()));
}

TEST_F(StateFile, ChangedSealBlockIsRefused) {
    create();
    const std::uint32_t zero = 0;
    poke(seal_at, &zero, sizeof zero);  // "stopped cleanly" cleared by damage
    const auto r = Storage::open(dir_, "p1");
    EXPECT_NE(message(r).find("header fails its checksum"), std::string::npos) << message(r);
}

// Issue 6 item 6: a 0-byte file no longer makes finsd start empty.
TEST_F(StateFile, EmptyFileIsRefusedAndKept) {
    create();
    fs::resize_file(state(), 0);
    const auto r = Storage::open(dir_, "p1");
    ASSERT_FALSE(r);
    EXPECT_NE(message(r).find("empty (0 bytes)"), std::string::npos) << message(r);
    EXPECT_TRUE(Storage::is_refusal(r.error()));
    EXPECT_TRUE(fs::exists(state()));
    EXPECT_EQ(fs::file_size(state()), 0u);
}

// Issue 18 item 5: the file emptied under a sealed Storage. The next access to a
// retained section ends the process with exit 4 and the line naming the file
// (storage_guard.hpp), never a SIGBUS; intact() sees it; a SIGBUS elsewhere is not taken.
TEST_F(StateFile, TruncatedUnderASealedStorageExits4WithTheLineNotASigbus) {
    auto s = Storage::open(dir_, "p1");
    ASSERT_TRUE(s) << message(s);
    auto a = (*s)->array<std::uint16_t>("a", 100, R);
    ASSERT_TRUE((*s)->seal());
    EXPECT_TRUE((*s)->intact());
    fs::resize_file(state(), 0);
    EXPECT_FALSE((*s)->intact());
    const std::string line = state_file_lost_message(state().string());
    std::string pattern;
    for (const char c : line)  // the whole line, literally (POSIX regex)
        if (c != '\n') pattern += std::string(std::strchr("().*+?^$[]{}|\\", c) ? "\\" : "") + c;
    EXPECT_EXIT(
        {
            volatile std::uint16_t* word = &a[99];
            *word = 1;
        },
        ::testing::ExitedWithCode(state_file_lost_exit_code), pattern);
}

TEST_F(StateFile, SetAsideRenamesNeverDeletesAndRespectsTheLock) {
    create();
    const std::string original = contents();
    {
        auto holder = Storage::open(dir_, "p1");
        ASSERT_TRUE(holder);
        const auto busy = Storage::set_aside(dir_);
        ASSERT_FALSE(busy);
        EXPECT_NE(busy.error().message().find("in use"), std::string::npos);
    }
    const auto first = Storage::set_aside(dir_);
    ASSERT_TRUE(first) << first.error().message();
    EXPECT_EQ(first->filename().string().rfind("finsd.state.replaced-", 0), 0u) << *first;
    EXPECT_FALSE(fs::exists(state()));
    std::ifstream f(*first, std::ios::binary);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(f), {}), original);

    create();  // a new file, moved aside within the same second: another name
    const auto second = Storage::set_aside(dir_);
    ASSERT_TRUE(second) << second.error().message();
    EXPECT_NE(*first, *second);
    EXPECT_TRUE(fs::exists(*first));
    EXPECT_FALSE(Storage::set_aside(dir_));  // nothing left to move
    EXPECT_FALSE(Storage::is_refusal(Storage::set_aside(dir_).error()));
}

// Issue 6 item 5: on a full file system the state file cannot be reserved: seal()
// says so, nothing is left behind, and no page of a sparse file is ever touched (a
// write to one would be a SIGBUS and end this test binary).
TEST_F(StateFile, FullFileSystemIsRefusedAtStartNotASigbus) {
    fs::create_directories(dir_);
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") != 0)
        GTEST_SKIP() << "cannot mount a 64 KiB tmpfs (" << std::strerror(errno)
                     << "): needs root or CAP_SYS_ADMIN";
    struct Unmount {
        fs::path dir;
        ~Unmount() { ::umount2(dir.c_str(), MNT_DETACH); }
    } unmount{dir_};
    {
        auto s = Storage::open(dir_, "p1");
        ASSERT_TRUE(s) << message(s);
        auto small = (*s)->array<std::uint16_t>("small", 100, R);
        auto big = (*s)->array<std::uint16_t>("big", 64 * 1024, R);  // 128 KiB
        small[0] = 1;                                                // reserved: fine
        big[big.size() - 1] = 1;  // a heap stand-in, never a file page
        const auto sealed = (*s)->seal();
        ASSERT_FALSE(sealed);
        EXPECT_NE(sealed.error().message().find("cannot reserve"), std::string::npos)
            << sealed.error().message();
        EXPECT_FALSE(Storage::is_refusal(sealed.error()));
    }
    EXPECT_TRUE(fs::is_empty(dir_));         // the unfinished file is gone, its space free
    auto again = Storage::open(dir_, "p1");  // and so at every restart
    ASSERT_TRUE(again);
    (*again)->array<std::uint16_t>("big", 64 * 1024, R);
    EXPECT_FALSE((*again)->seal());
}

// The same with a file size limit (RLIMIT_FSIZE), in a child: with SIGXFSZ ignored, as
// finsd does, the reservation fails with EFBIG and seal() says so.
TEST_F(StateFile, FileSizeLimitIsRefusedAtStart) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::signal(SIGXFSZ, SIG_IGN);
        const rlimit limit{64 * 1024, 64 * 1024};
        if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(2);
        auto s = Storage::open(dir_, "p1");
        if (!s) ::_exit(3);
        (*s)->array<std::uint16_t>("big", 64 * 1024, R);
        const auto sealed = (*s)->seal();
        if (sealed) ::_exit(4);
        ::_exit(sealed.error().message().find("cannot reserve") != std::string::npos ? 0 : 5);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << "child ended by signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 0);
    EXPECT_FALSE(fs::exists(state()));
}

// A sparse state file (an older finsd's, or a copy) gets its holes reserved at start.
TEST_F(StateFile, SparseExistingFileIsReservedAtStart) {
    create();
    const std::string bytes = contents();
    fs::remove(state());
    {
        std::ofstream f(state(), std::ios::binary);
        f.write(bytes.data(), 4096 + 200);  // header and "a"'s data; the rest a hole
    }
    fs::resize_file(state(), bytes.size());
    struct stat before {};
    ASSERT_EQ(::stat(state().c_str(), &before), 0);
    EXPECT_EQ(reopen_a()[99], 0xA099);
    struct stat after {};
    ASSERT_EQ(::stat(state().c_str(), &after), 0);
    EXPECT_LT(before.st_blocks * 512, static_cast<blkcnt_t>(bytes.size()));
    EXPECT_GE(after.st_blocks * 512, static_cast<blkcnt_t>(bytes.size()));
}

// A version 1 file (earlier finsd: no checksums, the same section table) is converted
// with its data, and kept as finsd.state.version1.
TEST_F(StateFile, Version1FileIsConvertedAndKept) {
    create();
    const std::uint32_t v1 = 1;
    const std::uint32_t zero = 0;
    poke(8, &v1, sizeof v1);
    poke(92, &zero, sizeof zero);  // version 1's reserved field, now the checksum
    const std::string tail(4096 - 3552, '\0');
    poke(3552, tail.data(), tail.size());
    const std::string old = contents();
    bool verified = true;
    EXPECT_EQ(reopen_a(&verified)[99], 0xA099);
    EXPECT_FALSE(verified);  // version 1 had no checksums to check
    std::ifstream kept(dir_ / "finsd.state.version1", std::ios::binary);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept), {}), old);
    EXPECT_FALSE(fs::exists(dir_ / "finsd.state.new"));
    EXPECT_EQ(reopen_a(&verified)[99], 0xA099);  // now a version 2 file, closed cleanly
    EXPECT_TRUE(verified);

    // An incomplete version 1 file (its creation never finished) is refused.
    fs::remove(dir_ / "finsd.state.version1");
    poke(8, &v1, sizeof v1);
    poke(12, &zero, sizeof zero);
    EXPECT_NE(message(Storage::open(dir_, "p1")).find("\"complete\" flag"), std::string::npos);
}

TEST_F(StateFile, PowerDurabilitySyncsOnEveryCommitProcessNever) {
    for (const auto durability : {Durability::process, Durability::power}) {
        auto s = Storage::open(dir_, "p1", {durability});
        ASSERT_TRUE(s);
        auto a = (*s)->array<std::uint16_t>("a", 100, R);
        ASSERT_TRUE((*s)->seal());
        a[0] = 1;
        EXPECT_TRUE((*s)->commit());
        EXPECT_TRUE((*s)->commit());
        EXPECT_EQ((*s)->syncs(), durability == Durability::power ? 2u : 0u);
    }
    Storage heap;
    EXPECT_TRUE(heap.commit());
    EXPECT_EQ(heap.syncs(), 0u);
}

}  // namespace
}  // namespace fins::plc::test
#endif
