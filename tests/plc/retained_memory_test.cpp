// IoMemory on a data directory: which regions survive a restart (retained, battery-
// backed on a CS/CJ) and which start at zero (cleared), end to end through Storage
// and through a whole Plc.
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "plc/io_memory_test_util.hpp"
#include "plc/plc.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc::test {
namespace {

namespace fs = std::filesystem;

class Retained : public ::testing::Test {
  protected:
    void SetUp() override {
        static std::atomic<int> n{0};
        dir_ = fs::temp_directory_path() /
               ("finskit-retained-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
        fs::remove_all(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    std::unique_ptr<Storage> open(const Profile& p) {
        auto s = Storage::open(dir_, p.name);
        EXPECT_TRUE(s) << s.error().message();
        return s ? std::move(*s) : std::make_unique<Storage>();
    }

    fs::path dir_;
};

// Writes a marker into every word area, flag and register IoMemory has.
void fill_everything(IoMemory& m) {
    for (Region r : {Region::cio, Region::work, Region::holding, Region::auxiliary, Region::dm,
                     Region::timer_counter}) {
        auto w = m.words(r);
        for (std::size_t i = 0; i < w.size(); ++i)
            w[i] = static_cast<std::uint16_t>(i + 1);
    }
    for (std::uint8_t b = 0; b < m.profile().em_banks; ++b) {
        auto w = m.words(Region::em, b);
        w.front() = static_cast<std::uint16_t>(0xE000 + b);
        w.back() = static_cast<std::uint16_t>(0xF000 + b);
    }
    for (std::uint32_t i = 0; i < counter_base + max_counters; ++i)
        m.set_completion_flag(i, true);
    EXPECT_TRUE(m.force_bit(Region::holding, 3, 4, true));
    EXPECT_TRUE(m.force_bit(Region::cio, 3, 4, true));
    EXPECT_TRUE(m.force_completion_flag(counter_base + 1, true));
    m.set_task_flag(3, true);
    m.set_task_status(3, 2);
    m.index_registers()[2] = 0x12345678;
    m.words(Region::data_register)[2] = 0x2222;
    EXPECT_TRUE(m.set_current_em_bank(2));
}

bool in_retained_aux(std::uint32_t word) {
    for (const auto& r : retained_auxiliary_words())
        if (word >= r.first && word < r.end) return true;
    return false;
}

TEST_F(Retained, CsCjRetainedAndClearedRegionsAcrossAReopen) {
    const Profile p = cj2h();
    {
        auto storage = open(p);
        IoMemory m(p, *storage);
        ASSERT_TRUE(storage->seal());
        fill_everything(m);
    }
    auto storage = open(p);
    IoMemory m(p, *storage);
    ASSERT_TRUE(storage->seal());
    EXPECT_TRUE(storage->restored());

    // Retained: H (the forced bit keeps its value, not its forced status), D, EM.
    for (std::size_t i = 0; i < p.holding_words; ++i)
        ASSERT_EQ(m.words(Region::holding)[i], (i + 1) | (i == 3 ? 0x10U : 0U)) << "H" << i;
    for (std::size_t i = 0; i < p.dm_words; ++i)
        ASSERT_EQ(m.words(Region::dm)[i], static_cast<std::uint16_t>(i + 1)) << "D" << i;
    for (std::uint8_t b = 0; b < p.em_banks; ++b) {
        EXPECT_EQ(m.words(Region::em, b).front(), 0xE000 + b);
        EXPECT_EQ(m.words(Region::em, b).back(), 0xF000 + b);
    }
    // Counters retained, timers cleared (PVs and completion flags).
    const auto tc = m.words(Region::timer_counter);
    for (std::uint32_t i = 0; i < counter_base + p.counters; ++i) {
        const bool counter = i >= counter_base;
        ASSERT_EQ(tc[i], counter ? i + 1 : 0u) << i;
        ASSERT_EQ(m.completion_flag(i), counter) << i;
    }
    // A: the battery-backed words only.
    const auto a = m.words(Region::auxiliary);
    for (std::uint32_t i = 0; i < p.auxiliary_words; ++i)
        ASSERT_EQ(a[i], in_retained_aux(i) ? i + 1 : 0u) << "A" << i;
    // Cleared: CIO, W, forced status everywhere, TK, IR, DR, the current EM bank.
    for (auto w : m.words(Region::cio))
        ASSERT_EQ(w, 0);
    for (auto w : m.words(Region::work))
        ASSERT_EQ(w, 0);
    for (Region r : {Region::cio, Region::work, Region::holding})
        for (auto f : m.forced_mask(r))
            ASSERT_EQ(f, 0);
    EXPECT_FALSE(m.is_completion_flag_forced(counter_base + 1));
    EXPECT_FALSE(m.task_flag(3));
    EXPECT_EQ(m.task_status(3), 0);
    EXPECT_EQ(m.index_registers()[2], 0u);
    EXPECT_EQ(m.words(Region::data_register)[2], 0);
    EXPECT_EQ(m.current_em_bank(), 0);
}

TEST_F(Retained, RetainedAuxiliaryWordsAreTheDocumentedOnes) {
    const auto r = retained_auxiliary_words();
    ASSERT_EQ(r.size(), 5u);
    EXPECT_TRUE(in_retained_aux(100) && in_retained_aux(199) && in_retained_aux(300));
    EXPECT_TRUE(in_retained_aux(510) && in_retained_aux(520) && in_retained_aux(523));
    EXPECT_TRUE(in_retained_aux(720) && in_retained_aux(749));
    for (std::uint32_t w :
         {0U, 99U, 200U, 299U, 301U, 448U, 509U, 521U, 522U, 524U, 719U, 750U, 959U})
        EXPECT_FALSE(in_retained_aux(w)) << w;
}

TEST_F(Retained, WritesThroughLocateAndWriteSurviveAndForcingDoesNot) {
    const Profile p = cj2h();
    {
        auto storage = open(p);
        IoMemory m(p, *storage);
        ASSERT_TRUE(storage->seal());
        EXPECT_EQ(write(m, at(0x82, 32767), 1, {0x12, 0x34}), 0);   // D32767
        EXPECT_EQ(write(m, at(0x68, 0), 1, {0x56, 0x78}), 0);       // E18_00000 (bank 0x18)
        EXPECT_EQ(write(m, at(0xB2, 511), 1, {0x9A, 0xBC}), 0);     // H511
        EXPECT_EQ(write(m, at(0x89, 0x8FFF), 1, {0x00, 0x99}), 0);  // C4095 PV
        EXPECT_EQ(write(m, at(0x89, 0x0FFF), 1, {0x00, 0x77}), 0);  // T4095 PV
        EXPECT_EQ(write(m, at(0xB3, 749), 1, {0x07, 0x49}), 0);     // A749
        EXPECT_EQ(write(m, at(0xB3, 750), 1, {0x07, 0x50}), 0);     // A750
        EXPECT_EQ(write(m, at(0x30, 10, 13), 1, {0x01}), 0);        // CIO10.13
    }
    auto storage = open(p);
    HeapMemory fresh(p);
    IoMemory m(p, *storage);
    ASSERT_TRUE(storage->seal());
    EXPECT_EQ(read(m, at(0x82, 32767), 1), (Bytes8{0x12, 0x34}));
    EXPECT_EQ(read(m, at(0x68, 0), 1), (Bytes8{0x56, 0x78}));
    EXPECT_EQ(read(m, at(0xB2, 511), 1), (Bytes8{0x9A, 0xBC}));
    EXPECT_EQ(read(m, at(0x89, 0x8FFF), 1), (Bytes8{0x00, 0x99}));
    EXPECT_EQ(read(m, at(0x89, 0x0FFF), 1), (Bytes8{0x00, 0x00}));
    EXPECT_EQ(read(m, at(0xB3, 749), 1), (Bytes8{0x07, 0x49}));
    EXPECT_EQ(read(m, at(0xB3, 750), 1), (Bytes8{0x00, 0x00}));
    EXPECT_EQ(read(m, at(0x30, 10, 13), 1), (Bytes8{0x00}));
    EXPECT_EQ(read(fresh, at(0x82, 32767), 1), (Bytes8{0x00, 0x00}));  // heap: nothing kept
}

TEST_F(Retained, WholePlcRestoresIoMemoryAndRefusesAnotherProfile) {
    const Profile p = *find_profile("cs1h");
    {
        Plc plc(p, open(p));
        ASSERT_TRUE(plc.storage().seal());
        EXPECT_FALSE(plc.storage().restored());
        plc.memory().words(Region::dm)[100] = 0x0100;
        plc.memory().words(Region::em, 12)[5] = 0x0C05;
        plc.memory().words(Region::work)[1] = 1;
    }
    {
        Plc plc(p, open(p));
        ASSERT_TRUE(plc.storage().seal());
        EXPECT_TRUE(plc.storage().restored());
        EXPECT_EQ(plc.memory().words(Region::dm)[100], 0x0100);
        EXPECT_EQ(plc.memory().words(Region::em, 12)[5], 0x0C05);
        EXPECT_EQ(plc.memory().words(Region::work)[1], 0);
    }
    // The same directory for another model: refused by Storage::open.
    const auto other = Storage::open(dir_, find_profile("cj2h")->name);
    ASSERT_FALSE(other);
    // A profile whose layout differs under the same id: refused by seal().
    Profile bigger = p;
    bigger.em_banks = 14;
    Plc plc(bigger, open(p));
    EXPECT_FALSE(plc.storage().seal());
}

// Issue 6 item 6: after a clean stop, a changed byte in the retained section of any
// model (I/O memory, parameter areas, program, clock, logs, messages) is refused, and
// the file is served again once the byte is back.
// Linux only: the test patches the state file through an fstream while Storage opens it;
// Windows refuses that sharing on purpose (storage_os.hpp, docs/windows.md).
#ifndef _WIN32
TEST_F(Retained, WholePlcEverySectionIsUnderTheChecksums) {
    const Profile p = *find_profile("cj1m");
    {
        Plc plc(p, open(p));
        ASSERT_TRUE(plc.storage().seal());
    }
    const fs::path file = dir_ / "finsd.state";
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    std::array<char, 4096> header{};
    f.read(header.data(), header.size());
    std::uint32_t count = 0;
    std::memcpy(&count, header.data() + 88, sizeof count);  // storage_format.hpp
    EXPECT_GE(count, 8u);
    for (std::uint32_t i = 0; i < count; ++i) {
        const char* entry = header.data() + 96 + 64 * i;
        std::uint64_t offset = 0;
        std::uint64_t size = 0;
        std::memcpy(&offset, entry + 40, sizeof offset);
        std::memcpy(&size, entry + 48, sizeof size);
        if (size == 0) continue;
        const auto at = static_cast<std::streamoff>(offset + size - 1);  // its last byte
        char byte = 0;
        f.seekg(at);
        f.get(byte);
        f.seekp(at);
        f.put(static_cast<char>(byte ^ 0x10));
        f.flush();
        const auto refused = Storage::open(dir_, p.name);
        EXPECT_FALSE(refused) << entry;
        f.seekp(at);
        f.put(byte);
        f.flush();
    }
    Plc plc(p, open(p));
    EXPECT_TRUE(plc.storage().seal());
    EXPECT_TRUE(plc.storage().checksums_verified());
}
#endif

TEST_F(Retained, EveryProfileRoundTripsItsLayout) {
    for (const auto& p : profiles()) {
        SCOPED_TRACE(p.name);
        fs::remove_all(dir_);
        {
            auto storage = open(p);
            IoMemory m(p, *storage);
            ASSERT_TRUE(storage->seal());
            m.words(Region::dm)[7] = 7;
            m.words(Region::holding)[7] = 8;
        }
        auto storage = open(p);
        IoMemory m(p, *storage);
        ASSERT_TRUE(storage->seal());
        EXPECT_EQ(m.words(Region::dm)[7], 7);
        EXPECT_EQ(m.words(Region::holding)[7], 8);
        EXPECT_EQ(m.words(Region::auxiliary).size(), p.auxiliary_words);
    }
}

}  // namespace
}  // namespace fins::plc::test
