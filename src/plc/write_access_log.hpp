// The FINS write access log of W342 5-3-30/5-3-31: who sent the last FINS write
// commands, kept in retained storage (it survives a restart, like the CPU Unit's
// battery-backed log).
//
// Rules of 5-3-30 "records stored in the access log":
// - a write from a node already in the log overwrites that node's record in place
//   (same network and node address; the unit address is updated with it);
// - a write from a new node adds a record at the end;
// - with 20 records stored, the oldest record is discarded first. "Oldest" is the record
//   written least recently (an overwritten record is a new record), and the records
//   after it move up one place.
// Record 0 is the first record of the log. Every access is logged whatever its end code:
// the manual logs "any access for FINS write commands".
#pragma once

#include <array>
#include <chrono>
#include <cstdint>

#include "fins/commands/error_log.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

class Clock;

class WriteAccessLog {
  public:
    WriteAccessLog(const Profile& profile, Storage& storage);
    // The clock whose reading stamps records (the Plc's own; it must outlive this).
    // Until it is set, records carry the UTC time of `now`.
    void use_clock(const Clock* clock) noexcept {
        clock_ = clock;
        last_.valid = false;
    }
    // Called by the dispatcher after every FINS write command (the commands marked
    // "Disabled" under network write protection in W342 5-1-2) with its end code.
    // At most 20 records are scanned or moved: O(1), no allocation.
    void record(const NodeAddress& source, CommandCode command, EndCode end_code,
                std::chrono::system_clock::time_point now) noexcept;

    [[nodiscard]] std::size_t size() const noexcept { return state_.count; }
    // Record `index` (0 = first); record 0 when out of range.
    [[nodiscard]] const WriteAccessRecord& at(std::size_t index) const noexcept {
        return state_.slots[index < state_.count ? index : 0].record;
    }
    void clear() noexcept {
        state_.count = 0;
        last_.valid = false;
    }

    struct Slot {
        WriteAccessRecord record;
        std::uint32_t sequence = 0;  // when it was last written, for "oldest"
    };
    struct State {
        std::uint32_t count = 0;
        std::uint32_t sequence = 0;
        std::array<Slot, log_max_records> slots{};
    };

  private:
    State& state_;
    const Clock* clock_ = nullptr;
    // Where the last record() wrote (valid while that slot holds state_.sequence).
    std::size_t newest_ = log_max_records;
    // What the last record() was given, kept here and not in the stored log: the same
    // writer and command again within its host second, the clock not set since, would
    // write the newest record again as it is. Skipped without a look at the clock or the
    // stored records (a plant's scenarios record every tick; those lines are cold).
    struct Last {
        NodeAddress source;
        CommandCode command;
        std::int64_t second = 0;
        std::uint64_t clock_version = 0;
        bool valid = false;
    };
    Last last_;
};

}  // namespace fins::plc
