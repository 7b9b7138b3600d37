// 21 01 .. 21 41: ERROR CLEAR, ERROR LOG READ/CLEAR, FINS WRITE ACCESS LOG READ/CLEAR
// (W342 5-3-27 .. 5-3-31, frames 6/2101 .. 6/2141; record layout seed 003 p.208).
#include "fins/commands/error_log.hpp"
#include "codec/command_codec.hpp"

#include <array>

namespace fins {

using codec::check_fixed;
using codec::empty_response;
using codec::end_code;
using codec::malformed;

namespace {

constexpr std::size_t read_size = 4;  // beginning record, number of records

// False for a nibble above 9.
bool bcd_field(std::uint8_t b, std::uint8_t& out) noexcept {
    const auto v = from_bcd(b);
    if (!v) return false;
    out = *v;
    return true;
}

// minute, second, day, hour, year, month: the order of both logs (5-3-28, 5-3-30).
void write_time(ByteWriter& w, const LogTime& t) noexcept {
    w.u8(to_bcd(t.minute));
    w.u8(to_bcd(t.second));
    w.u8(to_bcd(t.day));
    w.u8(to_bcd(t.hour));
    w.u8(to_bcd(t.year));
    w.u8(to_bcd(t.month));
}

bool read_time(ByteReader& r, LogTime& t) noexcept {
    bool ok = bcd_field(r.u8(), t.minute);
    ok = bcd_field(r.u8(), t.second) && ok;
    ok = bcd_field(r.u8(), t.day) && ok;
    ok = bcd_field(r.u8(), t.hour) && ok;
    ok = bcd_field(r.u8(), t.year) && ok;
    ok = bcd_field(r.u8(), t.month) && ok;
    return ok && !r.truncated();
}

bool read_record(ByteReader& r, ErrorLogRecord& rec) noexcept {
    rec.error_code = r.u16();
    rec.detail = r.u16();
    return read_time(r, rec.time);
}

bool read_record(ByteReader& r, WriteAccessRecord& rec) noexcept {
    rec.source.network = r.u8();
    rec.source.node = r.u8();
    rec.source.unit = r.u8();
    rec.reserved = r.u8();
    rec.command.main = r.u8();
    rec.command.sub = r.u8();
    return read_time(r, rec.time);
}

template <class Record>
Result<LogReadResponse<Record>> decode_log(Bytes data, std::size_t record_size,
                                           std::uint16_t requested) {
    ByteReader r(data);
    LogReadResponse<Record> out;
    out.max_records = r.u16();
    out.stored = r.u16();
    const std::uint16_t returned = r.u16();
    if (r.truncated() || returned > requested || r.remaining() != returned * record_size)
        return malformed();
    out.records.resize(returned);
    for (auto& rec : out.records)
        if (!read_record(r, rec)) return malformed();
    return out;
}

template <class C>
Result<C> decode_range(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, read_size)) return Unexpected(ec);
    ByteReader r(parameters);
    C c;
    c.first = r.u16();
    c.count = r.u16();
    return c;
}

constexpr bool F = true;   // fatal
constexpr bool N = false;  // non-fatal

// W342 5-3-27, both tables, in priority order. Bits: frames 6/0601 (fatal word: 15
// memory, 14 I/O bus, 13 duplication, 12 inner board, 11 I/O points overflow, 10 I/O
// setting, 9 program, 8 cycle time, 6 FALS; non-fatal word: 15 FAL, 14 duplex, 13
// interrupt task, 12 basic I/O, 10 PLC Setup, 9 I/O verification, 8 inner board, 7 CPU
// Bus Unit, 6 Special I/O Unit, 5 SYSMAC BUS, 4 battery, 3 CPU Bus Unit setting, 2
// Special I/O Unit setting). Codes with no bit there (flash memory, built-in analog,
// option board) report only through the error code.
constexpr std::array<ErrorCodeInfo, 29> error_codes{{
    {0x80F1, 0x80F1, "memory error", F, 15, true},
    {0x80C0, 0x80C7, "I/O bus error", F, 14, true},
    {0x80E9, 0x80E9, "duplication error", F, 13, true},
    {0x80EA, 0x80EA, "basic I/O word duplication", F, 13, true},
    {0x82F0, 0x82F0, "fatal Inner Board error", F, 12, true},
    {0x80E1, 0x80E1, "I/O points overflow", F, 11, true},
    {0x80E0, 0x80E0, "I/O setting error", F, 10, true},
    {0x80F0, 0x80F0, "program error", F, 9, true},
    {0x809F, 0x809F, "cycle time too long", F, 8, true},
    {0xC101, 0xC2FF, "FALS error", F, 6, true},
    {0x4101, 0x42FF, "FAL error", N, 15, false},
    {0x0003, 0x0003, "duplex power supply error", N, 14, false},
    {0x0010, 0x0010, "duplex bus error", N, 14, false},
    {0x0011, 0x0011, "duplex verification error", N, 14, false},
    {0x0600, 0x060F, "duplex communications error", N, 14, false},
    {0x008B, 0x008B, "interrupt task error", N, 13, false},
    {0x009A, 0x009A, "basic I/O error", N, 12, false},
    {0x009B, 0x009B, "PLC Setup error", N, 10, false},
    {0x00E7, 0x00E7, "I/O verification error", N, 9, false},
    {0x02F0, 0x02F0, "non-fatal Inner Board error", N, 8, false},
    {0x0200, 0x020F, "CPU Bus Unit error", N, 7, false},
    {0x0300, 0x035F, "Special I/O Unit error", N, 6, false},
    {0x00A0, 0x00A1, "SYSMAC BUS error", N, 5, false},
    {0x00F7, 0x00F7, "battery error", N, 4, false},
    {0x0400, 0x040F, "CPU Bus Unit setting error", N, 3, false},
    {0x0500, 0x055F, "Special I/O Unit setting error", N, 2, false},
    {0x00F1, 0x00F1, "flash memory error", N, -1, false},
    {0x008A, 0x008A, "built-in analog I/O error", N, -1, false},
    {0x00D1, 0x00D2, "Option Board error", N, -1, false},
}};
// FFFF and FFFE are requests to ERROR CLEAR, not errors: they are not in the table.
constexpr std::size_t table_size = error_codes.size();

}  // namespace

std::span<const ErrorCodeInfo> error_code_table() noexcept {
    return {error_codes.data(), table_size};
}

const ErrorCodeInfo* find_error_code(std::uint16_t code) noexcept {
    for (std::size_t i = 0; i < table_size; ++i)
        if (code >= error_codes[i].first && code <= error_codes[i].last) return &error_codes[i];
    return nullptr;
}

LogTime to_log_time(std::chrono::system_clock::time_point t) noexcept {
    using namespace std::chrono;
    // Keep the calendar arithmetic far from the representable limits (no overflow for
    // time_point::min()/max()); a log year has two BCD digits anyway.
    constexpr auto earliest = sys_days{year{1900} / 1 / 1};
    constexpr auto latest = sys_days{year{2199} / 12 / 31};
    if (t < earliest) t = earliest;
    if (t > latest) t = latest;
    const auto day = floor<days>(t);
    const year_month_day date{day};
    const hh_mm_ss time{floor<seconds>(t - day)};
    const int y = static_cast<int>(date.year());
    LogTime out;
    out.year = static_cast<std::uint8_t>(((y % 100) + 100) % 100);
    out.month = static_cast<std::uint8_t>(static_cast<unsigned>(date.month()));
    out.day = static_cast<std::uint8_t>(static_cast<unsigned>(date.day()));
    out.hour = static_cast<std::uint8_t>(time.hours().count());
    out.minute = static_cast<std::uint8_t>(time.minutes().count());
    out.second = static_cast<std::uint8_t>(time.seconds().count());
    return out;
}

void ErrorClear::encode(ByteWriter& w) const noexcept {
    w.u16(error_code);
}

Result<ErrorClear> ErrorClear::decode(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, 2)) return Unexpected(ec);
    ByteReader r(parameters);
    return ErrorClear{r.u16()};
}

Result<ErrorClear::Response> ErrorClear::decode_response(Bytes data) const {
    return empty_response(data);
}

void ErrorLogRecord::encode(ByteWriter& w) const noexcept {
    w.u16(error_code);
    w.u16(detail);
    write_time(w, time);
}

void WriteAccessRecord::encode(ByteWriter& w) const noexcept {
    w.u8(source.network);
    w.u8(source.node);
    w.u8(source.unit);
    w.u8(reserved);
    w.u8(command.main);
    w.u8(command.sub);
    write_time(w, time);
}

void ErrorLogRead::encode(ByteWriter& w) const noexcept {
    w.u16(first);
    w.u16(count);
}

Result<ErrorLogRead> ErrorLogRead::decode(Bytes parameters) noexcept {
    return decode_range<ErrorLogRead>(parameters);
}

Result<ErrorLogRead::Response> ErrorLogRead::decode_response(Bytes data) const {
    return decode_log<ErrorLogRecord>(data, error_record_size, count);
}

Result<ErrorLogClear> ErrorLogClear::decode(Bytes parameters) noexcept {
    if (!parameters.empty()) return end_code(EndCode::command_too_long);
    return ErrorLogClear{};
}

Result<ErrorLogClear::Response> ErrorLogClear::decode_response(Bytes data) const {
    return empty_response(data);
}

void WriteAccessLogRead::encode(ByteWriter& w) const noexcept {
    w.u16(first);
    w.u16(count);
}

Result<WriteAccessLogRead> WriteAccessLogRead::decode(Bytes parameters) noexcept {
    return decode_range<WriteAccessLogRead>(parameters);
}

Result<WriteAccessLogRead::Response> WriteAccessLogRead::decode_response(Bytes data) const {
    return decode_log<WriteAccessRecord>(data, access_record_size, count);
}

Result<WriteAccessLogClear> WriteAccessLogClear::decode(Bytes parameters) noexcept {
    if (!parameters.empty()) return end_code(EndCode::command_too_long);
    return WriteAccessLogClear{};
}

Result<WriteAccessLogClear::Response> WriteAccessLogClear::decode_response(Bytes data) const {
    return empty_response(data);
}

}  // namespace fins
