// The I/O memory of a CS/CJ CPU Unit (W342 5-2-2) at real sizes, and the element-level
// operations the 01 xx handlers need (W342 5-3-2 .. 5-3-6). No I/O and no clock: the
// clock pulses are derived from the time point the caller passes in.
//
// Storage regions (fins::Region):
//   cio, work, holding, auxiliary, dm   words, sized from the Profile
//   em                                  one run of words per bank the Profile has
//   em_current                          the bank named by current_em_bank() (default 0)
//   timer_counter                       PVs + completion flags; timers at index 0-4095,
//                                       counters at counter_base + n
//   task_flag                           32 flags + 32 status bytes
//   index_register / data_register      IR0-15 (32-bit) / DR0-15
//   clock_pulse, condition_flag,        derived or constant, read-only
//   access_error_flag
// Retention (W342 / CS/CJ operation manuals "status at power ON"; docs/finsd.md (profiles and
// configuration)): every region lives in a plc::Storage section. Retained (battery-backed, kept
// across restarts when finsd has a data directory): H, D, every EM bank, counter PVs and counter
// completion flags, and the Auxiliary Area words of retained_auxiliary_words(). Cleared at every
// start: CIO, W, timer PVs and completion flags, the rest of A, task flags, IR/DR, the current EM
// bank number, every forced-bit mask ("Forced Status Hold at Startup" left at its default, OFF). A
// region that is only partly retained (A, T/C PVs and flags) is one retained section whose cleared
// words the constructor zeroes, so the request path writes straight into the section either way.
//
// CIO, W, H and the T/C completion flags also carry a forced-bit mask. A forced bit's
// stored value is its forced value; FINS writes, fills and transfers leave forced
// bits unchanged (W342 5-3-4 "clear the force set/reset to write the data").
//
// Addressing goes through the one 5-2-2 table of the codec (fins::find_segment):
// locate() turns a wire address + count into an ElementRange or a FINS end code, and
// the other operations take only ranges locate() produced.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/memory_area.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

using TimePoint = std::chrono::system_clock::time_point;

// Storage index of counter C0000 inside Region::timer_counter.
inline constexpr std::uint32_t counter_base = 4096;
inline constexpr std::uint32_t max_timers = 4096;
inline constexpr std::uint32_t max_counters = 4096;
inline constexpr std::uint32_t task_count = 32;      // TK00-31
inline constexpr std::uint32_t register_count = 16;  // IR00-15, DR00-15
inline constexpr std::uint32_t clock_pulse_count = 5;

// Area 07 indexes (W342 5-2-2): clock pulses at words 0000-0004, condition flags at
// 1000-100F (0B-0D unused).
enum class ClockPulse : std::uint8_t {
    one_minute,
    one_second,
    point_two_second,
    point_one_second,
    point_zero_two_second
};
enum class ConditionFlag : std::uint8_t {
    error,
    carry,
    greater_than,
    equals,
    less_than,
    negative,
    overflow,
    underflow,
    greater_than_or_equals,
    not_equal,
    less_than_or_equals,
    always_off = 0x0E,
    always_on = 0x0F,
};

// Bytes per element of each element kind (W342 5-2-1 "Element Data Configurations").
std::uint8_t element_bytes(ElementKind kind) noexcept;

// Whether locate() checks that the range may be written (2101 on read-only words).
enum class Intent : std::uint8_t { read, write };

// A run of elements validated by IoMemory::locate(). `index` is the storage index of
// the first element: a word index for word and bit kinds, a flag/register index
// otherwise. Bit runs start at `bit` of that word and continue into the next word.
struct ElementRange {
    const MemoryAreaSegment* segment = nullptr;
    Region region = Region::dm;
    ElementKind kind = ElementKind::word;
    std::uint8_t bank = 0;  // EM bank; for em_current the bank current at locate()
    std::uint32_t index = 0;
    std::uint8_t bit = 0;
    std::uint32_t count = 0;

    [[nodiscard]] std::size_t byte_size() const noexcept {
        return std::size_t{count} * element_bytes(kind);
    }
};

// A run of Auxiliary Area words [first, end).
struct WordRange {
    std::uint32_t first = 0;
    std::uint32_t end = 0;
};

// The battery-backed Auxiliary Area words of a CS/CJ CPU Unit (status at power ON
// "Retained"): A100-A199 Error Log Area, A300 Error Log Pointer, A510-A511 Startup
// Time, A512-A513 Power Interruption Time, A514 Number of Power Interruptions,
// A515-A517 Operation Start Time, A518-A520 Operation End Time, A523 Total Power ON
// Time, A720-A749 Power ON Clock Data 1-10. Every other A word is cleared at start.
std::span<const WordRange> retained_auxiliary_words() noexcept;

class IoMemory {
  public:
    // Takes every region from `storage` (section names "io.*"; see the retention
    // table above). `storage` must outlive this object.
    IoMemory(Profile profile, Storage& storage);
    IoMemory(const IoMemory&) = delete;
    IoMemory& operator=(const IoMemory&) = delete;

    [[nodiscard]] const Profile& profile() const noexcept { return profile_; }

    // Validates `count` elements from `start` for the command group `use`:
    //   1101  unknown code, code this model lacks (EM bank, CJ2/CV code), or a code the
    //         command's area table does not list
    //   1103  start word outside every segment of the code or beyond the model's size;
    //         bit > 0F for bit access; bit != 00 for word or flag access
    //   1104  start valid but the last element runs past the segment / the model's size
    //   2101  Intent::write, count > 0 and the range starts in read-only words (A000-447)
    // count 0 is valid (an empty range) once the start address is.
    [[nodiscard]] Result<ElementRange> locate(const MemoryAddress& start, std::uint32_t count,
                                              AreaUse use, Intent intent) const noexcept;

    // Appends range.byte_size() bytes in the 5-2-1 encodings. Never fails once located.
    void read(const ElementRange& range, ByteWriter& out, TimePoint now) const noexcept;
    // 1003 when data is not count x element size; nothing is written then. Forced bits
    // keep their state. T/C PV writes leave the completion flags alone (W342 5-3-3).
    EndCode write(const ElementRange& range, Bytes data) noexcept;
    // Word ranges only. Filling T/C PVs turns their completion flags OFF (W342 5-3-4).
    EndCode fill(const ElementRange& range, std::uint16_t value) noexcept;
    // Word ranges of equal count. Behaves as a copy of the source taken before writing
    // (overlap safe); completion flags untouched (W342 5-3-6). Allocates count words.
    EndCode transfer(const ElementRange& source, const ElementRange& destination);

    // Direct access for the model, later commands and tests. These write stored values
    // as they are (no forcing rules); out-of-range indexes are ignored / read as 0.
    // Word storage of cio, work, holding, auxiliary, dm, em (bank), em_current,
    // timer_counter (the PVs) and data_register; empty for other regions or a missing bank.
    std::span<std::uint16_t> words(Region region, std::uint8_t bank = 0) noexcept;
    [[nodiscard]] std::span<const std::uint16_t> words(Region region,
                                                       std::uint8_t bank = 0) const noexcept;
    // Forced-bit mask of cio, work, holding (bit set = forced); empty for other regions.
    [[nodiscard]] std::span<const std::uint16_t> forced_mask(Region region) const noexcept;

    [[nodiscard]] bool completion_flag(std::uint32_t index) const noexcept;
    void set_completion_flag(std::uint32_t index, bool on) noexcept;

    [[nodiscard]] std::uint8_t current_em_bank() const noexcept { return current_em_bank_; }
    // False (and unchanged) when the profile has no such bank.
    bool set_current_em_bank(std::uint8_t bank) noexcept;

    [[nodiscard]] bool task_flag(std::uint32_t task) const noexcept;
    void set_task_flag(std::uint32_t task, bool on) noexcept;
    [[nodiscard]] std::uint8_t task_status(std::uint32_t task) const noexcept;
    void set_task_status(std::uint32_t task, std::uint8_t status) noexcept;

    std::span<std::uint32_t, register_count> index_registers() noexcept { return index_registers_; }
    [[nodiscard]] std::span<const std::uint32_t, register_count> index_registers() const noexcept {
        return index_registers_;
    }

    [[nodiscard]] bool access_error_flag() const noexcept { return access_error_flag_; }
    void set_access_error_flag(bool on) noexcept { access_error_flag_ = on; }

    // 1-min pulse ON during the first 30 s of each minute, 1 s pulse during the first
    // 0.5 s of each second, and so on: ON for the first half of each period.
    [[nodiscard]] static bool clock_pulse(ClockPulse pulse, TimePoint now) noexcept;
    // Always ON is 1, every other condition flag 0 (no program runs).
    [[nodiscard]] static bool condition_flag(ConditionFlag flag) noexcept;

    // Forcing (W342 5-3-44, used by 23 01 in issue 3). Bit forcing applies to cio, work
    // and holding; `word` is the word index in the region. Returns false for any other
    // region or an index outside the model.
    bool force_bit(Region region, std::uint32_t word, std::uint8_t bit, bool on) noexcept;
    bool release_bit(Region region, std::uint32_t word, std::uint8_t bit) noexcept;
    [[nodiscard]] bool is_forced(Region region, std::uint32_t word,
                                 std::uint8_t bit) const noexcept;
    bool force_completion_flag(std::uint32_t index, bool on) noexcept;
    bool release_completion_flag(std::uint32_t index) noexcept;
    [[nodiscard]] bool is_completion_flag_forced(std::uint32_t index) const noexcept;
    void release_all_forced() noexcept;

  private:
    struct Window {
        std::uint32_t first = 0;  // storage indexes [first, end)
        std::uint32_t end = 0;
    };
    [[nodiscard]] Window window(const MemoryAreaSegment& segment,
                                std::uint32_t index) const noexcept;
    [[nodiscard]] bool writable(const MemoryAreaSegment& segment, std::uint16_t word,
                                std::uint32_t index) const noexcept;
    std::span<std::uint16_t> forced_storage(Region region) noexcept;
    // Bank `bank` of em_; empty when the profile lacks it.
    std::span<std::uint16_t> em_bank(std::uint8_t bank) noexcept;

    // Element accessors used by read/write; indexes are range-checked (0 / ignored).
    [[nodiscard]] bool bit_at(const ElementRange& r, std::uint64_t position) const noexcept;
    [[nodiscard]] bool bit_forced_at(const ElementRange& r, std::uint64_t position) const noexcept;
    void store_bit(const ElementRange& r, std::uint64_t position, bool on) noexcept;
    [[nodiscard]] std::uint16_t word_at(const ElementRange& r, std::uint32_t index) const noexcept;
    void store_word(const ElementRange& r, std::uint32_t index, std::uint16_t value) noexcept;
    [[nodiscard]] std::uint8_t flag_at(const ElementRange& r, std::uint32_t index,
                                       TimePoint now) const noexcept;

    Profile profile_;
    // Sections of the Storage passed to the constructor.
    std::span<std::uint16_t> cio_, cio_forced_;
    std::span<std::uint16_t> work_, work_forced_;
    std::span<std::uint16_t> holding_, holding_forced_;
    std::span<std::uint16_t> auxiliary_;
    std::span<std::uint16_t> dm_;
    std::span<std::uint16_t> em_;  // every bank, em_bank_words each, bank 0 first
    std::uint8_t current_em_bank_ = 0;
    std::span<std::uint16_t> timer_counter_pv_;   // counter_base + counters entries
    std::span<std::uint16_t> completion_flags_;   // packed, 16 flags per word
    std::span<std::uint16_t> completion_forced_;  // packed forced mask
    // Cleared at every start like the sections above; plain members (nothing to keep).
    std::array<std::uint8_t, task_count> task_status_{};
    std::uint32_t task_flags_ = 0;
    std::array<std::uint32_t, register_count> index_registers_{};
    std::array<std::uint16_t, register_count> data_registers_{};
    bool access_error_flag_ = false;
};

}  // namespace fins::plc
