// RUN 04 01 and STOP 04 02 (W342 5-3-13, 5-3-14; frames 6/0401, 6/0402).
#include "fins/commands/operating_mode.hpp"
#include "codec/command_codec.hpp"

namespace fins {

using codec::empty_response;
using codec::end_code;

namespace {

constexpr std::size_t program_number_size = 2;
constexpr std::size_t run_max_size = program_number_size + 1;  // + mode byte

constexpr bool valid_mode(std::uint8_t mode) noexcept {
    return mode == static_cast<std::uint8_t>(RunMode::monitor) ||
           mode == static_cast<std::uint8_t>(RunMode::run);
}

}  // namespace

void Run::encode(ByteWriter& w) const noexcept {
    if (mode) {
        w.u16(program_number.value_or(all_programs));
        w.u8(static_cast<std::uint8_t>(*mode));
    } else if (program_number) {
        w.u16(*program_number);
    }
}

Result<Run> Run::decode(Bytes parameters) noexcept {
    // A lone byte is half a program number.
    if (parameters.size() == 1) return end_code(EndCode::command_too_short);
    if (parameters.size() > run_max_size) return end_code(EndCode::command_too_long);
    ByteReader r(parameters);
    Run c;
    if (r.remaining() >= program_number_size) {
        c.program_number = r.u16();
        if (*c.program_number != all_programs) return end_code(EndCode::program_missing);
    }
    if (r.remaining() == 1) {
        const auto mode = r.u8();
        if (!valid_mode(mode)) return end_code(EndCode::parameter_error);
        c.mode = static_cast<RunMode>(mode);
    }
    return c;
}

Result<Run::Response> Run::decode_response(Bytes data) const {
    return empty_response(data);
}

void Stop::encode(ByteWriter& w) const noexcept {
    if (program_number) w.u16(*program_number);
}

Result<Stop> Stop::decode(Bytes parameters) noexcept {
    if (parameters.size() == 1) return end_code(EndCode::command_too_short);
    if (parameters.size() > program_number_size) return end_code(EndCode::command_too_long);
    Stop c;
    if (parameters.size() == program_number_size) {
        ByteReader r(parameters);
        c.program_number = r.u16();
        if (*c.program_number != all_programs) return end_code(EndCode::program_missing);
    }
    return c;
}

Result<Stop::Response> Stop::decode_response(Bytes data) const {
    return empty_response(data);
}

}  // namespace fins
