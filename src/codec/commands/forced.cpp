// 23 01 FORCED SET/RESET and 23 02 FORCED SET/RESET CANCEL (W342 5-3-44, 5-3-45,
// frames 6/2301).
#include "codec/command_codec.hpp"
#include "fins/commands/forced.hpp"

namespace fins {

using codec::end_code;
using codec::malformed;

bool is_force_action(std::uint16_t value) noexcept {
    switch (static_cast<ForceAction>(value)) {
        case ForceAction::force_off:
        case ForceAction::force_on:
        case ForceAction::release_off:
        case ForceAction::release_on:
        case ForceAction::release:
            return true;
    }
    return false;
}

void ForcedSetReset::encode(ByteWriter& w) const noexcept {
    w.u16(static_cast<std::uint16_t>(items.size()));
    for (const auto& item : items) {
        w.u16(static_cast<std::uint16_t>(item.action));
        w.u8(item.address.area_code);
        w.u16(item.address.word);
        w.u8(item.address.bit);
    }
}

Result<ForcedSetReset> ForcedSetReset::decode(Bytes parameters) {
    if (parameters.size() < 2) return end_code(EndCode::command_too_short);
    ByteReader r(parameters);
    const std::size_t count = r.u16();
    if (r.remaining() != count * forced_item_size) return end_code(EndCode::elements_data_mismatch);
    ForcedSetReset c;
    c.items.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        ForcedItem item;
        item.action = static_cast<ForceAction>(r.u16());
        item.address.area_code = r.u8();
        item.address.word = r.u16();
        item.address.bit = r.u8();
        c.items.push_back(item);
    }
    return c;
}

Result<ForcedSetReset::Response> ForcedSetReset::decode_response(Bytes data) const {
    if (!data.empty()) return malformed();
    return EmptyResponse{};
}

Result<ForcedSetResetCancel> ForcedSetResetCancel::decode(Bytes parameters) noexcept {
    if (!parameters.empty()) return end_code(EndCode::command_too_long);
    return ForcedSetResetCancel{};
}

Result<ForcedSetResetCancel::Response> ForcedSetResetCancel::decode_response(Bytes data) const {
    if (!data.empty()) return malformed();
    return EmptyResponse{};
}

}  // namespace fins
