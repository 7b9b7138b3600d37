// The UM (user program) area of W342 5-3-10..5-3-12: its bytes, size per profile,
// protection.
//
// Size: Profile::program_kwords K words of 1,024 words of 2 bytes (W342 5-3-15 gives
// the program area size in K words, "1K words = 1,024 words"), so the CJ2H profile's
// 800 K words are 1,638,400 bytes, addresses 00000000-0018FFFF. The program area is that
// whole UM: its "last address" (bit 15 in a read response) is the last 4-byte unit of
// the UM, so a reader that stops on bit 15 gets every byte. The bytes are opaque: the
// virtual CPU does not execute them. A new UM is all zeros. The UM and the state below
// are battery-backed (Retention::retained).
//
// Rules (each pinned by a test naming its section):
//   read   2002 "Prohibit ... transferring program from PLC" set (5-3-10 comment);
//          1106 program number not FFFF; 110C bit 15 set in the command; 1102 address
//          or count not a multiple of 4; 110B more than 992 bytes (nothing read); 1103
//          address past the UM; past the end: the bytes up to the end + 1104.
//   write  2102 "Prohibit from overwriting to a protected program" set (5-3-11); 1106;
//          1001 more than 996 bytes; 1102; 1103; 1104 past the end (nothing written);
//          1003 data length != count. Bit 15 marks the last block of a download.
//   clear  2102 as for write; 1106; 110C clear code other than 00/10. Zeroes the UM,
//          records the task set (5-3-12 tables) and clears the protection (5-3-12:
//          "When the program area is cleared, protection will also be cleared"; the
//          handler also turns the PLC's UM read protection off).
// UM read protection (2002 on read), DIP switch write protection and the PROGRAM-mode
// condition (2206/2205 on write and clear) are the dispatcher's execution conditions.
#pragma once

#include <cstdint>
#include <span>

#include "fins/byte_io.hpp"
#include "fins/commands/program_area.hpp"
#include "fins/error.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

// A run of UM bytes validated by UserProgram::plan_*.
struct ProgramRange {
    std::uint32_t address = 0;
    std::uint16_t count = 0;     // bytes inside the UM (a read may be cut to fit)
    bool includes_last = false;  // the run holds the UM's last address
};

struct ProgramReadPlan {
    ProgramRange range;
    EndCode code = EndCode::normal_completion;  // 0000, or 1104 (cut at the end)
};

class UserProgram {
  public:
    UserProgram(const Profile& profile, Storage& storage);

    // UM size in bytes.
    [[nodiscard]] std::uint32_t size() const noexcept {
        return static_cast<std::uint32_t>(bytes_.size());
    }
    [[nodiscard]] std::span<const std::uint8_t> bytes() const noexcept { return bytes_; }
    std::span<std::uint8_t> bytes() noexcept { return bytes_; }

    [[nodiscard]] Result<ProgramReadPlan> plan_read(const ProgramAreaRead& command) const;
    [[nodiscard]] Result<ProgramRange> plan_write(const ProgramAreaWrite& command) const;
    // Validates program number, clear code and protection (2102, 1106, 110C).
    [[nodiscard]] EndCode check_clear(const ProgramAreaClear& command) const noexcept;

    void read(const ProgramRange& range, ByteWriter& out) const noexcept;
    // `data` holds range.count bytes. `last`: bit 15, the download is complete.
    void write(const ProgramRange& range, Bytes data, bool last) noexcept;
    // Zeroes the UM; `clear_code` 00 cyclic task 0 only, 10 with interrupt tasks.
    void clear(std::uint8_t clear_code) noexcept;

    // 5-3-12: the program has interrupt tasks (power, scheduled 2/3, I/O 100-131).
    [[nodiscard]] bool interrupt_tasks() const noexcept { return state_.interrupt_tasks != 0; }
    // True between a block written without bit 15 and the block with it.
    [[nodiscard]] bool download_in_progress() const noexcept {
        return state_.download_in_progress != 0;
    }

    // The CJ2 program-protection options (set with a Peripheral Device; tests and finsd
    // set them here). Both are cleared by PROGRAM AREA CLEAR.
    [[nodiscard]] bool prohibit_transfer() const noexcept { return state_.prohibit_transfer != 0; }
    void set_prohibit_transfer(bool on) noexcept { state_.prohibit_transfer = on ? 1 : 0; }
    [[nodiscard]] bool prohibit_overwrite() const noexcept {
        return state_.prohibit_overwrite != 0;
    }
    void set_prohibit_overwrite(bool on) noexcept { state_.prohibit_overwrite = on ? 1 : 0; }

  private:
    struct State {
        std::uint8_t interrupt_tasks = 0;
        std::uint8_t download_in_progress = 0;
        std::uint8_t prohibit_transfer = 0;
        std::uint8_t prohibit_overwrite = 0;
    };

    std::span<std::uint8_t> bytes_;
    State& state_;
};

}  // namespace fins::plc
