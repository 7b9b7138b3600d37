// CPU Unit errors: the error codes of W342 5-3-27 with their 06 01 status bits
// (5-3-17, frames 6/0601), the errors currently present, FAL/FALS numbers and messages
// (5-3-23), ERROR CLEAR (5-3-27), the 20-record error log (5-3-28, 5-3-29) and the
// end-code flag bits 6/7 (5-1-3).
//
// Model rules (what a CS/CJ CPU Unit does; each pinned by a test):
// - Priority is the order of error_code_table(): fatal before non-fatal, then the bit
//   order of the 06 01 words (memory error first ... FALS; FAL ... Special I/O Unit
//   setting error); equal priority: the newest occurrence wins.
// - Raising an error already present refreshes its message only (no new log record).
// - Every new occurrence appends a log record {code, detail, time}; the log keeps the
//   20 newest, record 0 the oldest (A100-A199 order). 21 03 resets the count only.
// - The battery error has a cause (the battery is low): clearing it while the cause
//   remains makes it occur again at once (5-3-27 comment), with a new log record.
// - Present errors live in cleared storage (gone after a restart), the log in retained
//   storage.
// Every operation that logs takes the host time `now`; the record shows the CPU Unit's
// clock at that moment once use_clock() names it (UTC of `now` until then).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "fins/commands/error_log.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

class Clock;

// The 5-3-27 code table lives in the codec (fins/commands/error_log.hpp).
using fins::error_code_table;
using fins::ErrorCodeInfo;
using fins::find_error_code;

inline constexpr std::uint16_t battery_error_code = 0x00F7;
inline constexpr std::uint16_t fal_code_base = 0x4100;   // FAL n  -> 4100 + n
inline constexpr std::uint16_t fals_code_base = 0xC100;  // FALS n -> C100 + n
inline constexpr std::size_t max_active_errors = 32;

struct ActiveError {
    std::uint16_t code = 0;
    std::uint16_t detail = 0;    // "error code 2" of the log record
    std::uint32_t sequence = 0;  // occurrence order, for ties in priority
    std::uint8_t priority = 0;   // index in error_code_table()
    std::uint8_t message_size = 0;
    std::array<char, 16> message{};  // FAL/FALS message, not padded

    [[nodiscard]] std::string_view text() const noexcept { return {message.data(), message_size}; }
};

class ErrorState {
  public:
    using TimePoint = std::chrono::system_clock::time_point;

    ErrorState(const Profile& profile, Storage& storage);
    // The clock whose reading stamps log records (the Plc's own; it must outlive this).
    void use_clock(const Clock* clock) noexcept { clock_ = clock; }

    // Bits 7 (fatal) and 6 (non-fatal CPU error) to OR into every end code (W342 5-1-3).
    [[nodiscard]] std::uint16_t end_code_flags() const noexcept { return state_.flags; }
    [[nodiscard]] std::uint16_t fatal_word() const noexcept { return state_.fatal_word; }
    [[nodiscard]] std::uint16_t non_fatal_word() const noexcept { return state_.non_fatal_word; }
    [[nodiscard]] bool has_fatal() const noexcept { return (state_.flags & 0x0080) != 0; }
    [[nodiscard]] bool has_non_fatal() const noexcept { return (state_.flags & 0x0040) != 0; }

    // Raises `code` (any code of error_code_table()). False for an unknown code, a
    // message over 16 bytes, or when max_active_errors are already present.
    bool raise(std::uint16_t code, TimePoint now, std::string_view message = {},
               std::uint16_t detail = 0);
    // FAL n / FALS n, n = 1-511 (FAL(006)/FALS(007)); false outside that range.
    bool raise_fal(std::uint16_t number, std::string_view message, TimePoint now);
    bool raise_fals(std::uint16_t number, std::string_view message, TimePoint now);

    // The battery: low raises 00F7 and keeps the cause; replaced removes the cause and
    // the error. Two causes are kept apart, the operator's (finsd ctl battery-error, the
    // [inject] table: set_battery_low) and a scenario's battery events: the battery is
    // low while either is, so a scenario event that ends does not replace a battery the
    // operator said is low, nor the operator's "off" one an event holds low.
    static constexpr std::uint8_t battery_cause_operator = 0x01;
    static constexpr std::uint8_t battery_cause_scenario = 0x02;
    void set_battery_low(bool low, TimePoint now) {
        set_battery_cause(battery_cause_operator, low, now);
    }
    void set_battery_cause(std::uint8_t cause, bool low, TimePoint now);
    [[nodiscard]] bool battery_low() const noexcept { return state_.battery_low != 0; }

    // Removes `code` if present (true). The battery error recurs while the cause remains.
    bool clear(std::uint16_t code, TimePoint now);
    // Removes every present error (the battery error recurs while the cause remains).
    void clear_all(TimePoint now);

    [[nodiscard]] std::span<const ActiveError> active() const noexcept {
        return {state_.items.data(), state_.count};
    }
    [[nodiscard]] bool is_active(std::uint16_t code) const noexcept;
    // The most serious present error, nullptr when none.
    [[nodiscard]] const ActiveError* most_serious() const noexcept;
    // The message of the most serious present FAL/FALS error ("" when none) (5-3-17).
    [[nodiscard]] std::string_view status_message() const noexcept;
    // The message of FALS n, else FAL n, while present (5-3-23); nullopt when neither is.
    [[nodiscard]] std::optional<std::string_view> fal_message(std::uint16_t number) const noexcept;

    // The error log, record 0 the oldest.
    [[nodiscard]] std::size_t log_size() const noexcept { return log_.count; }
    [[nodiscard]] const ErrorLogRecord& log_record(std::size_t index) const noexcept {
        return log_.records[index < log_.count ? index : 0];
    }
    void clear_log() noexcept { log_.count = 0; }  // the records stay (5-3-29)

    struct Present {
        std::array<ActiveError, max_active_errors> items{};
        std::uint32_t count = 0;
        std::uint32_t sequence = 0;
        std::uint16_t flags = 0;
        std::uint16_t fatal_word = 0;
        std::uint16_t non_fatal_word = 0;
        std::uint8_t battery_low = 0;
    };
    struct Log {
        std::uint32_t count = 0;
        std::array<ErrorLogRecord, log_max_records> records{};
    };

  private:
    void append_log(std::uint16_t code, std::uint16_t detail, TimePoint now) noexcept;
    void recompute() noexcept;

    Present& state_;
    Log& log_;
    const Clock* clock_ = nullptr;
};

}  // namespace fins::plc
