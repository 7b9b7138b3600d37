// The I/O memory area table of W342 5-2-2 and the per-command area tables of 5-3.
#include <map>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "fins/memory_area.hpp"

namespace fins {
namespace {

// Every code of 5-2-2 with its bytes per element (CS/CJ column, then CV column).
std::map<std::uint8_t, std::uint8_t> expected_codes() {
    std::map<std::uint8_t, std::uint8_t> m;
    auto range = [&](int first, int last, std::uint8_t size) {
        for (int c = first; c <= last; ++c)
            m[static_cast<std::uint8_t>(c)] = size;
    };
    range(0x30, 0x33, 1);
    range(0x70, 0x72, 1);
    range(0xB0, 0xB3, 2);
    range(0xF0, 0xF2, 4);
    m[0x09] = 1;
    m[0x49] = 1;
    m[0x89] = 2;
    m[0x02] = 1;
    m[0x82] = 2;
    range(0x20, 0x2F, 1);
    range(0xE0, 0xE8, 1);
    range(0xA0, 0xAF, 2);
    range(0x50, 0x5F, 2);
    range(0x60, 0x68, 2);
    m[0x0A] = 1;
    m[0x98] = 2;
    m[0xBC] = 2;
    m[0x06] = 1;
    m[0x46] = 1;
    m[0xDC] = 4;
    m[0x07] = 1;
    // CV mode
    m[0x00] = 1;
    m[0x40] = 1;
    m[0x80] = 2;
    m[0xC0] = 4;
    m[0x01] = 1;
    m[0x41] = 1;
    m[0x81] = 2;
    range(0x90, 0x97, 2);
    m[0x9C] = 2;
    return m;
}

std::uint32_t storage_index(const MemoryAreaSegment& s, std::uint16_t word) {
    return std::uint32_t{s.region_offset} + word - s.first_word;
}

TEST(MemoryArea, EveryCodeOf522WithItsElementSize) {
    const auto expected = expected_codes();
    for (int c = 0; c <= 0xFF; ++c) {
        const auto code = static_cast<std::uint8_t>(c);
        const auto it = expected.find(code);
        SCOPED_TRACE(c);
        EXPECT_EQ(is_memory_area_code(code), it != expected.end());
        EXPECT_EQ(element_size(code), it == expected.end() ? 0 : it->second);
    }
}

TEST(MemoryArea, RowsAreConsistent) {
    std::set<std::string_view> names;
    for (const auto& s : memory_area_table()) {
        SCOPED_TRACE(std::string(s.name));
        EXPECT_TRUE(names.insert(s.name).second) << "duplicate name";
        EXPECT_LE(s.first_word, s.last_word);
        EXPECT_TRUE(s.contains(s.writable_from));
        EXPECT_EQ(find_segment(s.code, s.first_word), &s);
        EXPECT_EQ(find_segment(s.code, s.last_word), &s);
        std::uint8_t size = 1;
        if (s.kind == ElementKind::word) size = 2;
        if (s.kind == ElementKind::word_forced || s.kind == ElementKind::double_word) size = 4;
        EXPECT_EQ(s.element_size, size);
        EXPECT_TRUE(s.allows(use_multi_read)) << "0104 reads every area (5-3-5)";
        if (s.region != Region::em) {
            EXPECT_EQ(s.em_bank, 0);
        }
    }
}

TEST(MemoryArea, CvModeRowsAndSharedCodes) {
    const std::set<int> cv{0x00, 0x40, 0x80, 0xC0, 0x01, 0x41, 0x81, 0x90,
                           0x91, 0x92, 0x93, 0x94, 0x95, 0x96, 0x97, 0x9C};
    int dm_rows = 0, em_current_rows = 0;
    for (const auto& s : memory_area_table()) {
        EXPECT_EQ(s.cv_mode, cv.count(s.code) == 1) << std::string(s.name);
        dm_rows += s.code == 0x82;
        em_current_rows += s.code == 0x98;
    }
    // 82 and 98 mean the same in both modes and are listed once.
    EXPECT_EQ(dm_rows, 1);
    EXPECT_EQ(em_current_rows, 1);
    // The CS rows come first (memory_area.hpp).
    bool seen_cv = false;
    for (const auto& s : memory_area_table()) {
        if (s.cv_mode)
            seen_cv = true;
        else
            EXPECT_FALSE(seen_cv) << std::string(s.name);
    }
}

struct Boundary {
    std::uint8_t code;
    std::uint16_t word;
    bool present;
};

TEST(MemoryArea, Boundaries) {
    const Boundary cases[] = {
        {0x30, 0x17FF, true},  {0x30, 0x1800, false}, {0xB0, 0x17FF, true},  {0xB0, 0x1800, false},
        {0xB1, 0x01FF, true},  {0xB1, 0x0200, false}, {0x72, 0x01FF, true},  {0x72, 0x0200, false},
        {0xB3, 0x03BF, true},  {0xB3, 0x03C0, false}, {0x09, 0x0FFF, true},  {0x09, 0x1000, false},
        {0x09, 0x7FFF, false}, {0x09, 0x8000, true},  {0x09, 0x8FFF, true},  {0x09, 0x9000, false},
        {0x89, 0x8FFF, true},  {0x49, 0x9000, false}, {0x82, 0x7FFF, true},  {0x82, 0x8000, false},
        {0x28, 0x7FFF, true},  {0xE8, 0x8000, false}, {0x5F, 0x7FFF, true},  {0x98, 0x8000, false},
        {0xBC, 0x01FF, false}, {0xBC, 0x0200, true},  {0xBC, 0x020F, true},  {0xBC, 0x0210, false},
        {0xBC, 0x0F00, true},  {0xBC, 0x0F01, false}, {0xDC, 0x00FF, false}, {0xDC, 0x0100, true},
        {0xDC, 0x010F, true},  {0xDC, 0x0110, false}, {0x06, 0x001F, true},  {0x46, 0x0020, false},
        {0x07, 0x0004, true},  {0x07, 0x0005, false}, {0x07, 0x1000, true},  {0x07, 0x100A, true},
        {0x07, 0x100B, false}, {0x07, 0x100D, false}, {0x07, 0x100E, true},  {0x07, 0x100F, true},
        {0x07, 0x1010, false}, {0x07, 0x2000, false}, {0x07, 0x2001, true},  {0x07, 0x2002, false},
        {0x00, 0x09FB, true},  {0x00, 0x09FC, false}, {0x00, 0x0AFF, false}, {0x00, 0x0B00, true},
        {0x80, 0x0EBF, true},  {0x80, 0x0EC0, false}, {0xC0, 0x0B00, false}, {0x01, 0x0FFF, true},
        {0x81, 0x1000, false}, {0x9C, 0x0002, false}, {0x9C, 0x0003, true},  {0x9C, 0x0006, true},
        {0x9C, 0x0007, false}, {0x03, 0x0000, false}, {0xFF, 0x0000, false},
    };
    for (const auto& c : cases) {
        EXPECT_EQ(find_segment(c.code, c.word) != nullptr, c.present)
            << std::hex << int(c.code) << " " << c.word;
    }
}

TEST(MemoryArea, A448IsTheFirstWritableWord) {
    for (std::uint8_t code : {std::uint8_t{0x33}, std::uint8_t{0xB3}}) {
        const auto* s = find_segment(code, 447);
        ASSERT_NE(s, nullptr);
        EXPECT_EQ(s->writable_from, 448);
        EXPECT_EQ(s->region, Region::auxiliary);
    }
    // CV mode: A000 is word 0B00, so A448 is 0CC0 and maps to the same storage index.
    for (std::uint8_t code : {std::uint8_t{0x00}, std::uint8_t{0x80}}) {
        const auto* s = find_segment(code, 0x0CC0);
        ASSERT_NE(s, nullptr);
        EXPECT_EQ(s->region, Region::auxiliary);
        EXPECT_EQ(s->writable_from, 0x0CC0);
        EXPECT_EQ(storage_index(*s, 0x0CC0), 448u);
        EXPECT_EQ(storage_index(*s, 0x0EBF), 959u);
    }
    // Every other area is writable from its first word.
    EXPECT_EQ(find_segment(0x82, 5)->writable_from, 0);
    EXPECT_EQ(find_segment(0xBC, 0x0200)->writable_from, 0x0200);
}

TEST(MemoryArea, RegionIndices) {
    // Timers then counters in one region (memory_area.hpp).
    EXPECT_EQ(storage_index(*find_segment(0x09, 0x0005), 0x0005), 5u);
    EXPECT_EQ(storage_index(*find_segment(0x89, 0x8005), 0x8005), 4096u + 5);
    EXPECT_EQ(storage_index(*find_segment(0x49, 0x8FFF), 0x8FFF), 4096u + 4095);
    EXPECT_EQ(storage_index(*find_segment(0x01, 0x0805), 0x0805), 4096u + 5);
    EXPECT_EQ(storage_index(*find_segment(0x81, 0x07FF), 0x07FF), 2047u);
    EXPECT_EQ(storage_index(*find_segment(0x07, 0x100E), 0x100E), 14u);
    EXPECT_EQ(storage_index(*find_segment(0x07, 0x100A), 0x100A), 10u);
    EXPECT_EQ(storage_index(*find_segment(0x07, 0x2001), 0x2001), 0u);
    EXPECT_EQ(storage_index(*find_segment(0xDC, 0x0103), 0x0103), 3u);
    EXPECT_EQ(storage_index(*find_segment(0xBC, 0x0203), 0x0203), 3u);
    EXPECT_EQ(storage_index(*find_segment(0x9C, 0x0004), 0x0004), 1u);
    EXPECT_EQ(find_segment(0xBC, 0x0F00)->region, Region::em_bank_number);
    EXPECT_EQ(find_segment(0x9C, 0x0006)->region, Region::em_bank_number);
    EXPECT_EQ(find_segment(0x9C, 0x0005)->region, Region::data_register);
    EXPECT_EQ(find_segment(0x07, 0x0004)->region, Region::clock_pulse);
    EXPECT_EQ(find_segment(0x07, 0x1000)->region, Region::condition_flag);
    EXPECT_EQ(find_segment(0x07, 0x2001)->region, Region::access_error_flag);
    EXPECT_EQ(find_segment(0x46, 0)->kind, ElementKind::task_status);
    EXPECT_EQ(find_segment(0xF0, 0)->kind, ElementKind::word_forced);
    EXPECT_EQ(find_segment(0x49, 0)->kind, ElementKind::flag_forced);
}

TEST(MemoryArea, EmBanks) {
    for (int b = 0; b <= 0x18; ++b) {
        const auto bit = static_cast<std::uint8_t>(b < 16 ? 0x20 + b : 0xE0 + b - 16);
        const auto word = static_cast<std::uint8_t>(b < 16 ? 0xA0 + b : 0x60 + b - 16);
        for (auto code : {bit, word}) {
            const auto* s = find_segment(code, 0);
            ASSERT_NE(s, nullptr) << b;
            EXPECT_EQ(s->region, Region::em);
            EXPECT_EQ(s->em_bank, b);
        }
        if (b < 16) {
            EXPECT_EQ(find_segment(static_cast<std::uint8_t>(0x50 + b), 0)->em_bank, b);
        }
        if (b < 8) {
            EXPECT_EQ(find_segment(static_cast<std::uint8_t>(0x90 + b), 0)->em_bank, b);
        }
    }
    EXPECT_EQ(find_segment(0xA3, 0)->name, "EM bank 3 word");
    EXPECT_EQ(find_segment(0xE0, 0)->name, "EM bank 10 bit");
    EXPECT_EQ(find_segment(0x98, 0)->region, Region::em_current);
    EXPECT_EQ(find_segment(0x0A, 0)->region, Region::em_current);
}

// The codes whose every row allows `use` (a code with mixed rows appears in neither set).
std::set<int> codes_allowing(AreaUse use) {
    std::set<int> out;
    for (const auto& s : memory_area_table())
        if (s.allows(use)) out.insert(s.code);
    return out;
}

std::set<int> span_of(std::initializer_list<std::pair<int, int>> ranges) {
    std::set<int> out;
    for (auto [a, b] : ranges)
        for (int c = a; c <= b; ++c)
            out.insert(c);
    return out;
}

TEST(MemoryArea, UsesFollowThePerCommandTables) {
    // 5-3-4 / 5-3-6: word codes only.
    EXPECT_EQ(codes_allowing(use_word_ops), span_of({{0xB0, 0xB3},
                                                     {0x89, 0x89},
                                                     {0x82, 0x82},
                                                     {0xA0, 0xAF},
                                                     {0x50, 0x5F},
                                                     {0x60, 0x68},
                                                     {0x98, 0x98},
                                                     {0x80, 0x81},
                                                     {0x90, 0x97}}));
    // 5-3-44: 30, 31, 32, 09; CV 00 and 01.
    EXPECT_EQ(codes_allowing(use_force), span_of({{0x30, 0x32}, {0x09, 0x09}, {0x00, 0x01}}));
    EXPECT_FALSE(find_segment(0x00, 0x0B00)->allows(use_force)) << "AR is not forceable";
    // 5-3-2: everything but the forced-status codes.
    auto read = span_of({{0, 255}});
    for (int c : {0x70, 0x71, 0x72, 0xF0, 0xF1, 0xF2, 0x49, 0x40, 0xC0, 0x41})
        read.erase(c);
    std::set<int> readable;
    for (int c : read)
        if (is_memory_area_code(static_cast<std::uint8_t>(c))) readable.insert(c);
    EXPECT_EQ(codes_allowing(use_read), readable);
    // 5-3-3: read's set minus 09, 06, 46, 07, CV 00/01 and the EM current bank number.
    EXPECT_EQ(codes_allowing(use_write), span_of({{0x30, 0x33},
                                                  {0xB0, 0xB3},
                                                  {0x89, 0x89},
                                                  {0x02, 0x02},
                                                  {0x82, 0x82},
                                                  {0x20, 0x2F},
                                                  {0xE0, 0xE8},
                                                  {0xA0, 0xAF},
                                                  {0x50, 0x5F},
                                                  {0x60, 0x68},
                                                  {0x0A, 0x0A},
                                                  {0x98, 0x98},
                                                  {0xDC, 0xDC},
                                                  {0xBC, 0xBC},
                                                  {0x80, 0x81},
                                                  {0x90, 0x97},
                                                  {0x9C, 0x9C}}));
    EXPECT_TRUE(find_segment(0xBC, 0x0200)->allows(use_write)) << "DR is writable";
    EXPECT_FALSE(find_segment(0xBC, 0x0F00)->allows(use_write)) << "bank number is not";
    EXPECT_TRUE(find_segment(0x9C, 0x0003)->allows(use_write));
    EXPECT_FALSE(find_segment(0x9C, 0x0006)->allows(use_write));
}

}  // namespace
}  // namespace fins
