// Operating mode changes: RUN 04 01 and STOP 04 02 (W342 5-3-13, 5-3-14; frames 6).
// Same command-type shape as fins/commands/memory_area.hpp.
//
// Both commands carry optional parameters, so one type covers every wire variant:
//   04 01                 -> MONITOR mode     (5-3-13 "Comments")
//   04 01 FFFF            -> MONITOR mode
//   04 01 FFFF 02 | 04    -> MONITOR | RUN mode
//   04 02 [FFFF]          -> PROGRAM mode     (5-3-14 "Comments")
// The program number is "always FFFF"; anything else answers 1106 (5-1-3 "program
// missing: FFFF hex was not specified"). A mode byte other than 02/04 answers 110C.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"  // EmptyResponse
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// The only program number a CS/CJ CPU Unit accepts (W342 5-3-13, 5-3-14).
inline constexpr std::uint16_t all_programs = 0xFFFF;

// The mode byte of 04 01 (W342 5-3-13 "Mode"). The enum keeps any byte a peer sent.
enum class RunMode : std::uint8_t { monitor = 0x02, run = 0x04 };

struct Run {
    static constexpr CommandCode code{0x04, 0x01};
    static constexpr std::string_view name = "RUN";
    using Response = EmptyResponse;

    // Sent when set; a mode without a program number is sent with FFFF before it.
    std::optional<std::uint16_t> program_number;
    std::optional<RunMode> mode;  // none: MONITOR

    // The mode the CPU Unit changes to: MONITOR unless the mode byte says RUN.
    [[nodiscard]] RunMode target() const noexcept { return mode.value_or(RunMode::monitor); }

    void encode(ByteWriter& w) const noexcept;
    // 0, 2 or 3 bytes. 1 byte: 1002; more than 3: 1001; program number not FFFF: 1106;
    // mode byte not 02/04: 110C (checked in that order).
    static Result<Run> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

struct Stop {
    static constexpr CommandCode code{0x04, 0x02};
    static constexpr std::string_view name = "STOP";
    using Response = EmptyResponse;

    // Omitted by default: Wireshark's dissector (which follows the CV-series manual)
    // expects STOP without parameters, and 5-3-14 accepts the command code alone.
    std::optional<std::uint16_t> program_number;

    void encode(ByteWriter& w) const noexcept;
    // 0 or 2 bytes. 1 byte: 1002; more than 2: 1001; program number not FFFF: 1106.
    static Result<Stop> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
