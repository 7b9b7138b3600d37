// CLOCK READ 07 01 and CLOCK WRITE 07 02 (W342 5-3-19, 5-3-20; frames 5.3, 6/0701,
// 6/0702).
#include "codec/command_codec.hpp"
#include "fins/commands/clock.hpp"

#include <array>

namespace fins {

using codec::end_code;
using codec::malformed;

namespace {

constexpr std::size_t clock_read_size = 7;  // 6 BCD fields + day of week
constexpr std::size_t clock_write_min = 5;  // year .. minute
constexpr std::size_t clock_write_max = 7;  // + second + day of week
constexpr std::uint8_t not_bcd = 0xFF;

std::uint8_t bcd_or_invalid(std::uint8_t value) noexcept {
    return value <= 99 ? to_bcd(value) : not_bcd;
}

}  // namespace

void ClockReadResponse::encode(ByteWriter& w) const noexcept {
    for (auto v : {time.year, time.month, time.day, time.hour, time.minute, time.second})
        w.u8(bcd_or_invalid(v));
    w.u8(time.day_of_week);
}

Result<ClockRead> ClockRead::decode(Bytes parameters) noexcept {
    if (!parameters.empty()) return end_code(EndCode::command_too_long);
    return ClockRead{};
}

Result<ClockRead::Response> ClockRead::decode_response(Bytes data) const {
    if (data.size() != clock_read_size) return malformed();
    std::array<std::uint8_t, clock_read_size - 1> fields{};
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const auto v = from_bcd(data[i]);
        if (!v) return malformed();
        fields[i] = *v;
    }
    Response r;
    r.time = {fields[0], fields[1], fields[2], fields[3], fields[4], fields[5], data[6]};
    return r;
}

void ClockWrite::encode(ByteWriter& w) const noexcept {
    for (auto v : {year, month, day, hour, minute})
        w.u8(bcd_or_invalid(v));
    if (second || day_of_week) w.u8(bcd_or_invalid(second.value_or(0)));
    if (day_of_week) w.u8(*day_of_week);
}

Result<ClockWrite> ClockWrite::decode(Bytes parameters) noexcept {
    if (parameters.size() < clock_write_min) return end_code(EndCode::command_too_short);
    if (parameters.size() > clock_write_max) return end_code(EndCode::command_too_long);
    // Year .. second are BCD; the day of week is a plain 00-06 byte (range-checked by
    // the CPU Unit model).
    const std::size_t bcd_fields = parameters.size() < clock_write_max ? parameters.size() : 6;
    std::array<std::uint8_t, 6> fields{};
    for (std::size_t i = 0; i < bcd_fields; ++i) {
        const auto v = from_bcd(parameters[i]);
        if (!v) return end_code(EndCode::parameter_error);
        fields[i] = *v;
    }
    ClockWrite c;
    c.year = fields[0];
    c.month = fields[1];
    c.day = fields[2];
    c.hour = fields[3];
    c.minute = fields[4];
    if (parameters.size() >= 6) c.second = fields[5];
    if (parameters.size() == clock_write_max) c.day_of_week = parameters[6];
    return c;
}

Result<ClockWrite::Response> ClockWrite::decode_response(Bytes data) const {
    if (!data.empty()) return malformed();
    return EmptyResponse{};
}

}  // namespace fins
