// Error log group 21 xx: ERROR CLEAR 21 01, ERROR LOG READ 21 02, ERROR LOG CLEAR
// 21 03, FINS WRITE ACCESS LOG READ 21 40, FINS WRITE ACCESS LOG CLEAR 21 41 (W342
// 5-3-27 .. 5-3-31, frames 6/2101 .. 6/2141). Same command-type shape as
// fins/commands/memory_area.hpp.
//
// Both logs hold at most 20 records. A read answers: maximum records (20), records
// stored, records returned, then the records. ERROR LOG READ answers 1104 together with
// the stored records when fewer exist than were asked for (5-3-28); the typed client
// send<ErrorLogRead>() reports that as an error, so read it with send_raw() and
// decode_response() when the short answer matters.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/commands/clock.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

inline constexpr std::uint16_t log_max_records = 20;   // "Always 20 records" (5-3-28, 5-3-30)
inline constexpr std::size_t error_record_size = 10;   // 5-3-28
inline constexpr std::size_t access_record_size = 12;  // 5-3-30
inline constexpr std::size_t log_read_header_size = 6;

// ERROR CLEAR codes with a meaning of their own (5-3-27).
inline constexpr std::uint16_t clear_all_errors = 0xFFFF;     // PROGRAM mode only
inline constexpr std::uint16_t clear_current_error = 0xFFFE;  // the highest-priority error

// A time stamp as the logs carry it: six BCD bytes on the wire, plain numbers here.
// year is the last two digits (full_year() of fins/commands/clock.hpp gives the rest).
struct LogTime {
    std::uint8_t year = 0;
    std::uint8_t month = 1;
    std::uint8_t day = 1;
    std::uint8_t hour = 0;
    std::uint8_t minute = 0;
    std::uint8_t second = 0;
    friend constexpr bool operator==(const LogTime&, const LogTime&) = default;
};

// UTC calendar time of `t`, years outside 1998-2097 wrapped to two digits. Pure
// arithmetic: no allocation, no time zone database.
LogTime to_log_time(std::chrono::system_clock::time_point t) noexcept;
// Conversions between LogTime and the CPU clock's reading (fins/commands/clock.hpp).
constexpr LogTime to_log_time(const ClockTime& t) noexcept {
    return LogTime{t.year, t.month, t.day, t.hour, t.minute, t.second};
}

// ---- 21 01 ----

// One row (or range) of the error codes ERROR CLEAR accepts (5-3-27), with the bit it
// shows in the 06 01 fatal / non-fatal error word (frames 6/0601).
struct ErrorCodeInfo {
    std::uint16_t first = 0;
    std::uint16_t last = 0;
    std::string_view name;           // e.g. "battery error"
    bool fatal = false;              // end-code bit 7, the CPU stops; else bit 6
    std::int8_t bit = -1;            // bit of the 06 01 fatal / non-fatal word, -1 none
    bool program_mode_only = false;  // ERROR CLEAR only in PROGRAM mode (5-3-27 table 2)
};

// Every code of both 5-3-27 lists except FFFF/FFFE (requests, not errors), most
// serious first: fatal before non-fatal, then in the bit order of the 06 01 words.
std::span<const ErrorCodeInfo> error_code_table() noexcept;
// nullptr for a code the lists do not name.
const ErrorCodeInfo* find_error_code(std::uint16_t code) noexcept;

struct ErrorClear {
    static constexpr CommandCode code{0x21, 0x01};
    static constexpr std::string_view name = "ERROR CLEAR";
    using Response = EmptyResponse;

    std::uint16_t error_code = clear_current_error;  // FFFF, FFFE or a 5-3-27 code

    void encode(ByteWriter& w) const noexcept;
    // 1002 shorter than 2 bytes, 1001 longer.
    static Result<ErrorClear> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

// ---- 21 02 / 21 40 shared parts ----

struct ErrorLogRecord {
    std::uint16_t error_code = 0;  // "error code 1": the 5-3-27 code
    std::uint16_t detail = 0;      // "error code 2": detail information
    LogTime time;
    void encode(ByteWriter& w) const noexcept;  // code 1, code 2, min sec day hour year month
    friend bool operator==(const ErrorLogRecord&, const ErrorLogRecord&) = default;
};

struct WriteAccessRecord {
    NodeAddress source;         // network, node, unit of the writer
    std::uint8_t reserved = 0;  // byte 3: always 00 from this server (frames 10 item 5)
    CommandCode command;        // the write command received
    LogTime time;
    void encode(
        ByteWriter& w) const noexcept;  // net node unit 00 MRC SRC min sec day hour year month
    friend bool operator==(const WriteAccessRecord&, const WriteAccessRecord&) = default;
};

template <class Record>
struct LogReadResponse {
    std::uint16_t max_records = log_max_records;
    std::uint16_t stored = 0;     // records in the log when the command ran
    std::vector<Record> records;  // the count field on the wire is records.size()
    void encode(ByteWriter& w) const noexcept {
        w.u16(max_records);
        w.u16(stored);
        w.u16(static_cast<std::uint16_t>(records.size()));
        for (const auto& r : records)
            r.encode(w);
    }
    friend bool operator==(const LogReadResponse&, const LogReadResponse&) = default;
};
using ErrorLogReadResponse = LogReadResponse<ErrorLogRecord>;
using WriteAccessLogReadResponse = LogReadResponse<WriteAccessRecord>;

// ---- 21 02 ----

struct ErrorLogRead {
    static constexpr CommandCode code{0x21, 0x02};
    static constexpr std::string_view name = "ERROR LOG READ";
    using Response = ErrorLogReadResponse;

    std::uint16_t first = 0;  // beginning record number, 0000 = oldest
    std::uint16_t count = log_max_records;

    void encode(ByteWriter& w) const noexcept;
    // 1002 shorter than 4 bytes, 1001 longer.
    static Result<ErrorLogRead> decode(Bytes parameters) noexcept;
    // Header + exactly (returned count) x 10 bytes, at most `count` records; BCD checked.
    Result<Response> decode_response(Bytes data) const;
};

struct ErrorLogClear {
    static constexpr CommandCode code{0x21, 0x03};
    static constexpr std::string_view name = "ERROR LOG CLEAR";
    using Response = EmptyResponse;

    void encode(ByteWriter&) const noexcept {}
    static Result<ErrorLogClear> decode(Bytes parameters) noexcept;  // 1001 if any
    Result<Response> decode_response(Bytes data) const;
};

// ---- 21 40 / 21 41 ----

struct WriteAccessLogRead {
    static constexpr CommandCode code{0x21, 0x40};
    static constexpr std::string_view name = "FINS WRITE ACCESS LOG READ";
    using Response = WriteAccessLogReadResponse;

    std::uint16_t first = 0;
    std::uint16_t count = log_max_records;

    void encode(ByteWriter& w) const noexcept;
    static Result<WriteAccessLogRead> decode(Bytes parameters) noexcept;
    // Header + exactly (returned count) x 12 bytes, at most `count` records; BCD checked.
    Result<Response> decode_response(Bytes data) const;
};

struct WriteAccessLogClear {
    static constexpr CommandCode code{0x21, 0x41};
    static constexpr std::string_view name = "FINS WRITE ACCESS LOG CLEAR";
    using Response = EmptyResponse;

    void encode(ByteWriter&) const noexcept {}
    static Result<WriteAccessLogClear> decode(Bytes parameters) noexcept;  // 1001 if any
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
