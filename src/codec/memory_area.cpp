// The I/O memory area table of W342 5-2-2, one row per address segment.
//
// Which commands accept a row (AreaUse) follows the per-command area tables:
//   read       5-3-2:  every code except those with forced status (70-72, F0-F2, 49;
//                      CV 40, C0, 41)
//   write      5-3-3:  read's set minus completion flags (09), task flags (06, 46),
//                      clock pulses/condition flags (07), the EM current bank number and
//                      the CV bit code 00 ("---" in the CV column)
//   word ops   5-3-4, 5-3-6 (and 22 0A): B0-B3, 89, 82, A0-AF, 50-5F, 60-68, 98;
//                      CV 80, 81, 90-97
//   multi read 5-3-5:  all
//   force      5-3-44: 30, 31, 32, 09; CV 00 (CIO part only) and 01
#include <array>
#include <cstddef>

#include "fins/memory_area.hpp"

namespace fins {
namespace {

constexpr std::uint8_t R = use_read;
constexpr std::uint8_t W = use_write;
constexpr std::uint8_t O = use_word_ops;
constexpr std::uint8_t M = use_multi_read;
constexpr std::uint8_t F = use_force;

// W342 5-2-1 "Element Data Configurations".
constexpr std::uint8_t size_of(ElementKind kind) {
    switch (kind) {
        case ElementKind::word:
            return 2;
        case ElementKind::word_forced:
        case ElementKind::double_word:
            return 4;
        default:
            return 1;
    }
}

#define FINS_BANKS_0_F(pre, post)                                                           \
    pre "0" post, pre "1" post, pre "2" post, pre "3" post, pre "4" post, pre "5" post,     \
        pre "6" post, pre "7" post, pre "8" post, pre "9" post, pre "A" post, pre "B" post, \
        pre "C" post, pre "D" post, pre "E" post, pre "F" post
#define FINS_BANKS_10_18(pre, post)                                                           \
    pre "10" post, pre "11" post, pre "12" post, pre "13" post, pre "14" post, pre "15" post, \
        pre "16" post, pre "17" post, pre "18" post

constexpr std::string_view em_bit_names[] = {FINS_BANKS_0_F("EM bank ", " bit"),
                                             FINS_BANKS_10_18("EM bank ", " bit")};
constexpr std::string_view em_word_names[] = {FINS_BANKS_0_F("EM bank ", " word"),
                                              FINS_BANKS_10_18("EM bank ", " word")};
constexpr std::string_view em_cj2_word_names[] = {FINS_BANKS_0_F("EM bank ", " word (CJ2)")};
constexpr std::string_view em_cv_word_names[] = {
    "CV EM bank 0 word", "CV EM bank 1 word", "CV EM bank 2 word", "CV EM bank 3 word",
    "CV EM bank 4 word", "CV EM bank 5 word", "CV EM bank 6 word", "CV EM bank 7 word"};
#undef FINS_BANKS_0_F
#undef FINS_BANKS_10_18

constexpr std::uint16_t max_dm_word = 0x7FFF;     // D/E 00000-32767
constexpr std::uint16_t counter_index = 4096;     // counters follow the 4,096 timers
constexpr std::uint16_t cs_ar_writable = 0x01C0;  // A448
constexpr std::uint16_t cv_ar_first = 0x0B00;     // CV mode: A000 is word 0B00
constexpr std::uint16_t cv_ar_writable = 0x0CC0;  // CV mode: A448

struct Extra {
    std::uint16_t region_offset = 0;
    std::uint16_t writable_from = 0xFFFF;  // 0xFFFF: every word from first_word
    std::uint8_t em_bank = 0;
    bool cv = false;
};

struct Table {
    std::array<MemoryAreaSegment, 160> rows{};
    std::size_t size = 0;

    constexpr void add(std::uint8_t code, std::string_view name, Region region, ElementKind kind,
                       std::uint16_t first, std::uint16_t last, std::uint8_t uses, Extra x = {}) {
        rows[size++] = MemoryAreaSegment{code,
                                         name,
                                         region,
                                         kind,
                                         size_of(kind),
                                         x.em_bank,
                                         first,
                                         last,
                                         x.region_offset,
                                         x.writable_from == 0xFFFF ? first : x.writable_from,
                                         uses,
                                         x.cv};
    }
};

using K = ElementKind;
using G = Region;

constexpr Table build() {
    Table t;
    // CS/CJ mode, in the order of 5-2-2.
    t.add(0x30, "CIO bit", G::cio, K::bit, 0x0000, 0x17FF, R | W | M | F);
    t.add(0x31, "WR bit", G::work, K::bit, 0x0000, 0x01FF, R | W | M | F);
    t.add(0x32, "HR bit", G::holding, K::bit, 0x0000, 0x01FF, R | W | M | F);
    t.add(0x33, "AR bit", G::auxiliary, K::bit, 0x0000, 0x03BF, R | W | M,
          {.writable_from = cs_ar_writable});
    t.add(0x70, "CIO bit with forced status", G::cio, K::bit_forced, 0x0000, 0x17FF, M);
    t.add(0x71, "WR bit with forced status", G::work, K::bit_forced, 0x0000, 0x01FF, M);
    t.add(0x72, "HR bit with forced status", G::holding, K::bit_forced, 0x0000, 0x01FF, M);
    t.add(0xB0, "CIO word", G::cio, K::word, 0x0000, 0x17FF, R | W | O | M);
    t.add(0xB1, "WR word", G::work, K::word, 0x0000, 0x01FF, R | W | O | M);
    t.add(0xB2, "HR word", G::holding, K::word, 0x0000, 0x01FF, R | W | O | M);
    t.add(0xB3, "AR word", G::auxiliary, K::word, 0x0000, 0x03BF, R | W | O | M,
          {.writable_from = cs_ar_writable});
    t.add(0xF0, "CIO word with forced status", G::cio, K::word_forced, 0x0000, 0x17FF, M);
    t.add(0xF1, "WR word with forced status", G::work, K::word_forced, 0x0000, 0x01FF, M);
    t.add(0xF2, "HR word with forced status", G::holding, K::word_forced, 0x0000, 0x01FF, M);
    t.add(0x09, "timer completion flag", G::timer_counter, K::flag, 0x0000, 0x0FFF, R | M | F);
    t.add(0x09, "counter completion flag", G::timer_counter, K::flag, 0x8000, 0x8FFF, R | M | F,
          {.region_offset = counter_index});
    t.add(0x49, "timer completion flag with forced status", G::timer_counter, K::flag_forced,
          0x0000, 0x0FFF, M);
    t.add(0x49, "counter completion flag with forced status", G::timer_counter, K::flag_forced,
          0x8000, 0x8FFF, M, {.region_offset = counter_index});
    t.add(0x89, "timer PV", G::timer_counter, K::word, 0x0000, 0x0FFF, R | W | O | M);
    t.add(0x89, "counter PV", G::timer_counter, K::word, 0x8000, 0x8FFF, R | W | O | M,
          {.region_offset = counter_index});
    t.add(0x02, "DM bit", G::dm, K::bit, 0x0000, max_dm_word, R | W | M);
    // 82 and 98 are the same code in CV mode; one row serves both.
    t.add(0x82, "DM word", G::dm, K::word, 0x0000, max_dm_word, R | W | O | M);
    for (std::uint8_t b = 0; b < 0x19; ++b) {
        const auto code = static_cast<std::uint8_t>(b < 0x10 ? 0x20 + b : 0xE0 + b - 0x10);
        t.add(code, em_bit_names[b], G::em, K::bit, 0x0000, max_dm_word, R | W | M, {.em_bank = b});
    }
    for (std::uint8_t b = 0; b < 0x19; ++b) {
        const auto code = static_cast<std::uint8_t>(b < 0x10 ? 0xA0 + b : 0x60 + b - 0x10);
        t.add(code, em_word_names[b], G::em, K::word, 0x0000, max_dm_word, R | W | O | M,
              {.em_bank = b});
    }
    // 5-2-2 note 2: CJ2 CPU Units also accept 50-5F for banks 0-F.
    for (std::uint8_t b = 0; b < 0x10; ++b)
        t.add(static_cast<std::uint8_t>(0x50 + b), em_cj2_word_names[b], G::em, K::word, 0x0000,
              max_dm_word, R | W | O | M, {.em_bank = b});
    t.add(0x0A, "EM current bank bit", G::em_current, K::bit, 0x0000, max_dm_word, R | W | M);
    t.add(0x98, "EM current bank word", G::em_current, K::word, 0x0000, max_dm_word, R | W | O | M);
    t.add(0xBC, "DR", G::data_register, K::word, 0x0200, 0x020F, R | W | M);
    t.add(0xBC, "EM current bank number", G::em_bank_number, K::word, 0x0F00, 0x0F00, R | M);
    t.add(0x06, "task flag", G::task_flag, K::flag, 0x0000, 0x001F, R | M);
    t.add(0x46, "task status", G::task_flag, K::task_status, 0x0000, 0x001F, R | M);
    t.add(0xDC, "IR", G::index_register, K::double_word, 0x0100, 0x010F, R | W | M);
    t.add(0x07, "clock pulse", G::clock_pulse, K::flag, 0x0000, 0x0004, R | M);
    // 1000-100A: ER, CY, >, =, <, N, OF, UF, >=, <>, <=; 100B-100D do not exist.
    t.add(0x07, "condition flag", G::condition_flag, K::flag, 0x1000, 0x100A, R | M);
    t.add(0x07, "Always OFF/ON flag", G::condition_flag, K::flag, 0x100E, 0x100F, R | M,
          {.region_offset = 14});
    t.add(0x07, "access error flag", G::access_error_flag, K::flag, 0x2001, 0x2001, R | M);

    // CV mode (CVM1/CV column of 5-2-2), accepted by CS/CJ CPU Units.
    const Extra cv{.cv = true};
    t.add(0x00, "CV CIO bit", G::cio, K::bit, 0x0000, 0x09FB, R | M | F, cv);
    t.add(0x00, "CV AR bit", G::auxiliary, K::bit, cv_ar_first, 0x0EBF, R | M,
          {.writable_from = cv_ar_writable, .cv = true});
    t.add(0x40, "CV CIO bit with forced status", G::cio, K::bit_forced, 0x0000, 0x09FB, M, cv);
    t.add(0x80, "CV CIO word", G::cio, K::word, 0x0000, 0x09FB, R | W | O | M, cv);
    t.add(0x80, "CV AR word", G::auxiliary, K::word, cv_ar_first, 0x0EBF, R | W | O | M,
          {.writable_from = cv_ar_writable, .cv = true});
    t.add(0xC0, "CV CIO word with forced status", G::cio, K::word_forced, 0x0000, 0x09FB, M, cv);
    t.add(0x01, "CV timer completion flag", G::timer_counter, K::flag, 0x0000, 0x07FF, R | M | F,
          cv);
    t.add(0x01, "CV counter completion flag", G::timer_counter, K::flag, 0x0800, 0x0FFF, R | M | F,
          {.region_offset = counter_index, .cv = true});
    t.add(0x41, "CV timer completion flag with forced status", G::timer_counter, K::flag_forced,
          0x0000, 0x07FF, M, cv);
    t.add(0x41, "CV counter completion flag with forced status", G::timer_counter, K::flag_forced,
          0x0800, 0x0FFF, M, {.region_offset = counter_index, .cv = true});
    t.add(0x81, "CV timer PV", G::timer_counter, K::word, 0x0000, 0x07FF, R | W | O | M, cv);
    t.add(0x81, "CV counter PV", G::timer_counter, K::word, 0x0800, 0x0FFF, R | W | O | M,
          {.region_offset = counter_index, .cv = true});
    for (std::uint8_t b = 0; b < 8; ++b)
        t.add(static_cast<std::uint8_t>(0x90 + b), em_cv_word_names[b], G::em, K::word, 0x0000,
              max_dm_word, R | W | O | M, {.em_bank = b, .cv = true});
    t.add(0x9C, "CV DR", G::data_register, K::word, 0x0003, 0x0005, R | W | M, cv);
    t.add(0x9C, "CV EM current bank number", G::em_bank_number, K::word, 0x0006, 0x0006, R | M, cv);
    return t;
}

constexpr Table table = build();

// Rows of one code, for O(1) lookup by code.
struct CodeRange {
    std::uint8_t begin = 0;
    std::uint8_t count = 0;
};

constexpr std::array<CodeRange, 256> build_index() {
    std::array<CodeRange, 256> rows_of{};
    for (std::size_t i = 0; i < table.size; ++i) {
        auto& r = rows_of[table.rows[i].code];
        if (r.count == 0) r.begin = static_cast<std::uint8_t>(i);
        ++r.count;
    }
    return rows_of;
}
constexpr auto code_index = build_index();

// The index assumes the rows of one code are adjacent, ascending and never overlap, and
// that every row of a code has the same element size.
constexpr bool well_formed() {
    for (std::size_t i = 0; i < table.size; ++i) {
        const auto& s = table.rows[i];
        const auto& r = code_index[s.code];
        if (i < r.begin || i >= std::size_t{r.begin} + r.count) return false;
        if (s.first_word > s.last_word) return false;
        if (s.writable_from < s.first_word || s.writable_from > s.last_word) return false;
        if (i > r.begin) {
            const auto& prev = table.rows[i - 1];
            if (prev.last_word >= s.first_word) return false;
            if (prev.element_size != s.element_size) return false;
        }
    }
    return table.size <= table.rows.size();
}
static_assert(well_formed(), "memory area table rows of one code must be adjacent and sorted");

}  // namespace

std::span<const MemoryAreaSegment> memory_area_table() noexcept {
    return std::span<const MemoryAreaSegment>(table.rows.data(), table.size);
}

const MemoryAreaSegment* find_segment(std::uint8_t code, std::uint16_t word) noexcept {
    const auto& r = code_index[code];
    for (std::size_t i = r.begin; i < std::size_t{r.begin} + r.count; ++i)
        if (table.rows[i].contains(word)) return &table.rows[i];
    return nullptr;
}

bool is_memory_area_code(std::uint8_t code) noexcept {
    return code_index[code].count != 0;
}

std::uint8_t element_size(std::uint8_t code) noexcept {
    const auto& r = code_index[code];
    return r.count == 0 ? std::uint8_t{0} : table.rows[r.begin].element_size;
}

}  // namespace fins
