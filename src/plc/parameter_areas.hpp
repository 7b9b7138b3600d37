// Parameter areas of W342 5-3-7..5-3-9: PLC Setup (8010), I/O table (8012), routing
// tables (8013), CPU Bus Unit setup (8002) and the whole range (8000), laid out as in
// fins/commands/parameter_area.hpp. All 8,000 words are one battery-backed section
// (Retention::retained); a new CPU Unit starts with zeros everywhere, which is the
// PLC Setup's default state and empty routing tables.
//
// The commands go through plan_* (validation, as IoMemory::locate does for 01 xx) and
// then read/write/clear on the validated range. Rules (each pinned by a test naming
// its section):
//   read   1101 unknown code; 110C bit 15 set in the command; 1103 start past the end;
//          count 0: nothing read, normal. More than 498 words: 498 are read + 110B (the
//          seed's "1108" is not a 5-1-3 code; 110B "response too long" is what it
//          names). Past the end: the words up to the end + 1104. Both send data.
//   write  1101, 1103, 1001 count > 498 (nothing written), 1104 past the end, 1003
//          data != 2 x count, 110C bit 15 set without the last word or clear with it;
//          count 0: nothing written, normal. Areas other than the routing tables are
//          written whole (5-3-7 "must be read or written in its entirety"): blocks go
//          to a staging buffer in sequence from word 0000, and the block holding the
//          last word (bit 15) makes the whole area live at once ("or no data will be
//          written"). A block out of sequence answers 110C and drops the staged data;
//          one area is staged at a time (a block at word 0000 starts over).
//          The routing tables are written in place.
//   clear  1101; 1103 beginning word not 0000; 110C clear data not 0000; count 0:
//          normal, nothing cleared; 1104 more words than the area; 110C fewer ("must be
//          cleared in its entirety"). Bit 15 of the count is ignored.
// Clearing a CJ I/O table "reflects the mounted Units" (5-3-9); the virtual CPU Unit has
// no Basic I/O Units, so that is zeros as well.
// I/O table words may be written or cleared only in PROGRAM mode (5-3-8, 5-3-9): the
// handler checks ParameterRange::io_table against the mode (2206 RUN, 2205 MONITOR).
#pragma once

#include <cstdint>
#include <span>

#include "fins/byte_io.hpp"
#include "fins/commands/parameter_area.hpp"
#include "fins/error.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

// A run of words validated by ParameterAreas::plan_*.
struct ParameterRange {
    const ParameterAreaInfo* area = nullptr;
    std::uint16_t start = 0;
    std::uint16_t count = 0;     // words inside the area (a read may be cut to fit)
    bool includes_last = false;  // the run holds the area's last word
    bool io_table = false;       // the run touches I/O table words
};

// What a read sends: the range, and the end code that goes out with the data (0000,
// 1104 past the end, 110B over 498 words).
struct ParameterReadPlan {
    ParameterRange range;
    EndCode code = EndCode::normal_completion;
};

class ParameterAreas {
  public:
    ParameterAreas(const Profile& profile, Storage& storage);

    [[nodiscard]] Result<ParameterReadPlan> plan_read(const ParameterAreaRead& command) const;
    [[nodiscard]] Result<ParameterRange> plan_write(const ParameterAreaWrite& command) const;
    [[nodiscard]] Result<ParameterRange> plan_clear(const ParameterAreaClear& command) const;

    // Appends range.count words, big-endian.
    void read(const ParameterRange& range, ByteWriter& out) const noexcept;
    // `data` holds 2 x range.count bytes (plan_write checked it). 0000, or 110C for a
    // block out of sequence in a whole area.
    EndCode write(const ParameterRange& range, Bytes data) noexcept;
    // Zeroes the range (the whole area) and drops staged data.
    void clear(const ParameterRange& range) noexcept;

    // The live words of an area (empty for an unknown code): for tests, finsd and
    // the other models.
    std::span<std::uint16_t> words(std::uint16_t area_code) noexcept;
    [[nodiscard]] std::span<const std::uint16_t> words(std::uint16_t area_code) const noexcept;
    // True while a whole-area write has started but not reached its last word.
    [[nodiscard]] bool staging() const noexcept { return staging_.area != 0; }

  private:
    // A whole-area write in progress; area 0 = none. Volatile (cleared at power-on).
    struct Staging {
        std::uint16_t area = 0;
        std::uint16_t next = 0;
    };

    std::span<std::uint16_t> all_;     // 8,000 words, retained
    std::span<std::uint16_t> staged_;  // 8,000 words, cleared at start
    Staging& staging_;
};

}  // namespace fins::plc
