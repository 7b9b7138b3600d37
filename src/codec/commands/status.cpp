// CYCLE TIME READ 06 20 (W342 5-3-18; frames 6/0620).
#include "codec/command_codec.hpp"
#include "fins/commands/status.hpp"

namespace fins {

using codec::end_code;

namespace {

constexpr std::size_t cycle_times_size = 3 * 4;  // average, maximum, minimum

}  // namespace

void CycleTimeReadResponse::encode(ByteWriter& w) const noexcept {
    if (!times) return;
    w.u32(times->average);
    w.u32(times->maximum);
    w.u32(times->minimum);
}

void CycleTimeRead::encode(ByteWriter& w) const noexcept {
    w.u8(static_cast<std::uint8_t>(operation));
}

Result<CycleTimeRead> CycleTimeRead::decode(Bytes parameters) noexcept {
    if (parameters.empty()) return end_code(EndCode::command_too_short);
    if (parameters.size() > 1) return end_code(EndCode::command_too_long);
    const auto value = parameters[0];
    if (value != static_cast<std::uint8_t>(CycleTimeOperation::initialize) &&
        value != static_cast<std::uint8_t>(CycleTimeOperation::read))
        return end_code(EndCode::parameter_error);
    return CycleTimeRead{static_cast<CycleTimeOperation>(value)};
}

Result<CycleTimeRead::Response> CycleTimeRead::decode_response(Bytes data) const {
    const auto malformed = Unexpected(make_error_code(ClientError::malformed_response));
    if (operation == CycleTimeOperation::initialize) {
        if (!data.empty()) return malformed;
        return Response{};
    }
    if (data.size() != cycle_times_size) return malformed;
    ByteReader r(data);
    CycleTimes t;
    t.average = r.u32();
    t.maximum = r.u32();
    t.minimum = r.u32();
    return Response{t};
}

}  // namespace fins
