// The I/O memory area table of W342 5-2-2, as data.
//
// One row ("segment") per contiguous address range of one memory area code: a code
// can have several (09 = timers at 0000-0FFF and counters at 8000-8FFF; BC = DR at
// 0200-020F and the current EM bank number at 0F00). Client and server both use this
// table: the client to know element sizes, the virtual PLC to validate and map every
// address. Address ranges are the "memory address" column (word part of the 3-byte
// address); region_offset maps them onto the storage region.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

namespace fins {

// The 4-byte I/O memory address of W342 5-2-1: area code, word (big-endian), bit.
struct MemoryAddress {
    std::uint8_t area_code = 0;
    std::uint16_t word = 0;
    std::uint8_t bit = 0;  // 00-0F for bit access; 00 for words and completion flags
    friend constexpr bool operator==(const MemoryAddress&, const MemoryAddress&) = default;
};
inline constexpr std::size_t memory_address_size = 4;

// Storage regions of a CS/CJ CPU Unit's I/O memory.
enum class Region : std::uint8_t {
    cio,                // CIO 0000-6143
    work,               // W000-511
    holding,            // H000-511
    auxiliary,          // A000-959 (A000-447 read-only)
    timer_counter,      // T0000-4095 then C0000-4095 (index 4096+n): flag and PV
    dm,                 // D00000-32767
    em,                 // EM bank n, 00000-32767
    em_current,         // EM current bank, 00000-32767
    em_bank_number,     // the current EM bank number (one word)
    task_flag,          // TK00-31
    index_register,     // IR00-15 (32-bit)
    data_register,      // DR00-15
    clock_pulse,        // 1 min, 1 s, 0.2 s, 0.1 s, 0.02 s
    condition_flag,     // ER, CY, >, =, <, N, OF, UF, >=, <>, <=, (B-D reserved) Always OFF, Always ON
    access_error_flag,  // the Access Error Flag
};

// How one element is encoded in read/write data (W342 5-2-1 "Element Data Configurations").
enum class ElementKind : std::uint8_t {
    bit,           // 1 byte: 00 OFF / 01 ON; address bit 00-0F
    bit_forced,    // 1 byte: bit 0 value, bit 1 forced
    word,          // 2 bytes
    word_forced,   // 4 bytes: forced-bit mask word, then value word (UNCONFIRMED order, libfins)
    flag,          // 1 byte 00/01, one per word address, bit must be 00 (T/C completion, TK, 07)
    flag_forced,   // 1 byte: bit 0 value, bit 1 forced (T/C completion with forced status)
    task_status,   // 1 byte task status (46)
    double_word,   // 4 bytes, big-endian 32-bit (index registers)
};

// Which commands may name a segment (the per-command area tables of 5-3-2..5-3-6, 5-3-44).
enum AreaUse : std::uint8_t {
    use_read = 0x01,        // 01 01 MEMORY AREA READ
    use_write = 0x02,       // 01 02 MEMORY AREA WRITE
    use_word_ops = 0x04,    // 01 03 FILL, 01 05 TRANSFER, 22 0A MEMORY AREA-FILE TRANSFER
    use_multi_read = 0x08,  // 01 04 MULTIPLE MEMORY AREA READ
    use_force = 0x10,       // 23 01 FORCED SET/RESET
};

struct MemoryAreaSegment {
    std::uint8_t code;            // memory area code
    std::string_view name;        // e.g. "CIO bit", "EM bank 3 word"
    Region region;
    ElementKind kind;
    std::uint8_t element_size;    // bytes per element in read/write data
    std::uint8_t em_bank;         // bank number for Region::em, else 0
    std::uint16_t first_word;     // first word address accepted in the command
    std::uint16_t last_word;      // last word address accepted (inclusive)
    std::uint16_t region_offset;  // storage index of first_word inside the region
    std::uint16_t writable_from;  // first writable word address (A448 for AR); first_word if all
    std::uint8_t uses;            // AreaUse bits
    bool cv_mode;                 // CVM1/CV-series code accepted by CS/CJ

    [[nodiscard]] constexpr bool contains(std::uint16_t word) const noexcept {
        return word >= first_word && word <= last_word;
    }
    [[nodiscard]] constexpr bool allows(AreaUse u) const noexcept { return (uses & u) != 0; }
    [[nodiscard]] constexpr bool bit_addressed() const noexcept {
        return kind == ElementKind::bit || kind == ElementKind::bit_forced;
    }
};

// Every segment of 5-2-2 (CS/CJ mode, then CV mode).
std::span<const MemoryAreaSegment> memory_area_table() noexcept;

// The segment of `code` containing `word`, or nullptr (unknown code or word outside
// every segment of that code).
const MemoryAreaSegment* find_segment(std::uint8_t code, std::uint16_t word) noexcept;

// True when the code appears in the table at all.
bool is_memory_area_code(std::uint8_t code) noexcept;

// Bytes per element for a code, 0 for an unknown code (all segments of a code agree).
std::uint8_t element_size(std::uint8_t code) noexcept;

}  // namespace fins
