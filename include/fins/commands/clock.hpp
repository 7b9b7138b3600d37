// Time data access: CLOCK READ 07 01 and CLOCK WRITE 07 02 (W342 5-3-19, 5-3-20;
// frames 5.3 and 6/0701, 6/0702). Same command-type shape as fins/commands/memory_area.hpp.
//
// Wire format: one BCD byte each for year (last two digits), month, day, hour (00-23),
// minute, second, then the day of week 00 (Sunday) .. 06 (Saturday). Fields here hold
// the binary values; the codec converts. Year 98 and 99 are 1998 and 1999, 00-97 are
// 2000-2097 (5-3-19 "Year").
//
// 07 02 takes 5, 6 or 7 bytes (5-3-20 "Comments"): second omitted -> 00 and the day of
// week keeps its previous value; day of week omitted -> previous value kept. The PLC
// checks ranges and refuses the whole write (110C) if any field is wrong; it does not
// cross-check the day of week against the date. A byte that is not BCD is such a wrong
// field: the decoder answers 110C for it, the range checks belong to the CPU Unit model.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"  // EmptyResponse
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// 0-99 -> packed BCD (values above 99 are not representable; the caller checks).
constexpr std::uint8_t to_bcd(std::uint8_t value) noexcept {
    return static_cast<std::uint8_t>(((value / 10) << 4) | (value % 10));
}
// Packed BCD -> 0-99, or nothing when a nibble is above 9.
constexpr std::optional<std::uint8_t> from_bcd(std::uint8_t bcd) noexcept {
    const unsigned high = bcd >> 4U;
    const unsigned low = bcd & 0x0FU;
    if (high > 9 || low > 9) return std::nullopt;
    return static_cast<std::uint8_t>(high * 10 + low);
}
// 5-3-19 "Year": 98, 99 -> 1998, 1999; 00-97 -> 2000-2097.
constexpr int full_year(std::uint8_t two_digits) noexcept {
    return two_digits >= 98 ? 1900 + two_digits : 2000 + two_digits;
}

enum class DayOfWeek : std::uint8_t {
    sunday,
    monday,
    tuesday,
    wednesday,
    thursday,
    friday,
    saturday
};

// A clock reading in binary: year = last two digits.
struct ClockTime {
    std::uint8_t year = 0;
    std::uint8_t month = 1;
    std::uint8_t day = 1;
    std::uint8_t hour = 0;
    std::uint8_t minute = 0;
    std::uint8_t second = 0;
    std::uint8_t day_of_week = 0;  // DayOfWeek
    friend bool operator==(const ClockTime&, const ClockTime&) = default;
};

struct ClockReadResponse {
    ClockTime time;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const ClockReadResponse&, const ClockReadResponse&) = default;
};

struct ClockRead {
    static constexpr CommandCode code{0x07, 0x01};
    static constexpr std::string_view name = "CLOCK READ";
    using Response = ClockReadResponse;

    void encode(ByteWriter&) const noexcept {}
    // No parameters: anything is 1001.
    static Result<ClockRead> decode(Bytes parameters) noexcept;
    // Exactly 7 bytes, the first six valid BCD.
    Result<Response> decode_response(Bytes data) const;
};

struct ClockWrite {
    static constexpr CommandCode code{0x07, 0x02};
    static constexpr std::string_view name = "CLOCK WRITE";
    using Response = EmptyResponse;

    std::uint8_t year = 0;  // last two digits
    std::uint8_t month = 1;
    std::uint8_t day = 1;
    std::uint8_t hour = 0;
    std::uint8_t minute = 0;
    std::optional<std::uint8_t> second;       // none: 00
    std::optional<std::uint8_t> day_of_week;  // none: keep the CPU Unit's value

    // Encodes 5, 6 or 7 bytes; a day of week without a second is sent with second 00.
    // Values above 99 cannot be sent as BCD and are sent as 0xFF (refused with 110C).
    void encode(ByteWriter& w) const noexcept;
    // 5 to 7 bytes: fewer 1002, more 1001; a non-BCD byte 110C. Ranges are not
    // checked here (month 13 decodes; the CPU Unit refuses it).
    static Result<ClockWrite> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
