// 06 01 CPU UNIT STATUS READ and the 09 20 family (W342 5-3-17, 5-3-21 .. 5-3-23,
// frames 6/0601 and 6/0920).
//
// Server side (decode): 1002 shorter than the fixed part, 1001 longer, 110C for a
// parameter word that names no variant. Client side (decode_response): any length or
// echo mismatch is malformed_response.
#include <bit>

#include "codec/command_codec.hpp"
#include "fins/commands/diagnostics.hpp"

namespace fins {

using codec::end_code;
using codec::malformed;

namespace {

constexpr std::uint16_t variant_mask = 0xC000;
constexpr std::uint16_t reserved_msg_bits = 0x3F00;  // bits 13-8 of read / clear
constexpr std::uint16_t variant_read = 0x0000;
constexpr std::uint16_t variant_clear = message_clear_bit;
constexpr std::uint16_t variant_fal = fal_read_bit;

// The one parameter word of 09 20, or 1002/1001.
Result<std::uint16_t> parameter_word(Bytes parameters) noexcept {
    if (parameters.size() < 2) return end_code(EndCode::command_too_short);
    if (parameters.size() > 2) return end_code(EndCode::command_too_long);
    ByteReader r(parameters);
    return r.u16();
}

std::string text_of(Bytes b) {
    return std::string(b.begin(), b.end());
}

}  // namespace

void CpuUnitStatusReadResponse::encode(ByteWriter& w) const noexcept {
    w.u8(status);
    w.u8(mode);
    w.u16(fatal_errors);
    w.u16(non_fatal_errors);
    w.u16(messages);
    w.u16(error_code);
    w.text(error_message, error_message_size);
}

Result<CpuUnitStatusRead> CpuUnitStatusRead::decode(Bytes parameters) noexcept {
    if (!parameters.empty()) return end_code(EndCode::command_too_long);
    return CpuUnitStatusRead{};
}

Result<CpuUnitStatusRead::Response> CpuUnitStatusRead::decode_response(Bytes data) const {
    if (data.size() != cpu_status_size) return malformed();
    ByteReader r(data);
    Response s;
    s.status = r.u8();
    s.mode = r.u8();
    s.fatal_errors = r.u16();
    s.non_fatal_errors = r.u16();
    s.messages = r.u16();
    s.error_code = r.u16();
    s.error_message = text_of(r.bytes(error_message_size));
    return s;
}

void MessageReadResponse::encode(ByteWriter& w) const noexcept {
    w.u16(messages);
    for (const auto& t : texts)
        w.text(t, msg_text_size);
}

void MessageRead::encode(ByteWriter& w) const noexcept {
    w.u16(messages);
}

Result<MessageRead> MessageRead::decode(Bytes parameters) noexcept {
    auto word = parameter_word(parameters);
    if (!word) return Unexpected(word.error());
    if ((*word & variant_mask) != variant_read || (*word & reserved_msg_bits) != 0)
        return end_code(EndCode::parameter_error);
    return MessageRead{static_cast<std::uint8_t>(*word)};
}

Result<MessageRead::Response> MessageRead::decode_response(Bytes data) const {
    ByteReader r(data);
    const std::uint16_t word = r.u16();
    // 5-3-21: the answer's bits are the messages returned, in ascending order.
    if (r.truncated() || word > 0xFF) return malformed();
    Response out;
    out.messages = static_cast<std::uint8_t>(word);
    const auto n = static_cast<std::size_t>(std::popcount(out.messages));
    if (r.remaining() != n * msg_text_size) return malformed();
    for (std::size_t i = 0; i < n; ++i)
        out.texts.push_back(text_of(r.bytes(msg_text_size)));
    return out;
}

void MessageClear::encode(ByteWriter& w) const noexcept {
    w.u16(static_cast<std::uint16_t>(message_clear_bit | messages));
}

Result<MessageClear> MessageClear::decode(Bytes parameters) noexcept {
    auto word = parameter_word(parameters);
    if (!word) return Unexpected(word.error());
    if ((*word & variant_mask) != variant_clear || (*word & reserved_msg_bits) != 0)
        return end_code(EndCode::parameter_error);
    return MessageClear{static_cast<std::uint8_t>(*word)};
}

Result<MessageClear::Response> MessageClear::decode_response(Bytes data) const {
    if (!data.empty()) return malformed();
    return EmptyResponse{};
}

void FalFalsReadResponse::encode(ByteWriter& w) const noexcept {
    w.u16(static_cast<std::uint16_t>(fal_read_bit | (number & fal_number_mask)));
    w.text(message, error_message_size);
}

void FalFalsRead::encode(ByteWriter& w) const noexcept {
    w.u16(static_cast<std::uint16_t>(fal_read_bit | (number & fal_number_mask)));
}

Result<FalFalsRead> FalFalsRead::decode(Bytes parameters) noexcept {
    auto word = parameter_word(parameters);
    if (!word) return Unexpected(word.error());
    if ((*word & variant_mask) != variant_fal) return end_code(EndCode::parameter_error);
    return FalFalsRead{static_cast<std::uint16_t>(*word & fal_number_mask)};
}

Result<FalFalsRead::Response> FalFalsRead::decode_response(Bytes data) const {
    if (data.size() != 2 + error_message_size) return malformed();
    ByteReader r(data);
    const std::uint16_t word = r.u16();
    // Accept the number with or without bit 15: frames only says "same layout".
    if ((word & fal_number_mask) != (number & fal_number_mask) || (word & message_clear_bit) != 0)
        return malformed();
    return Response{static_cast<std::uint16_t>(word & fal_number_mask),
                    text_of(r.bytes(error_message_size))};
}

Result<MessageCommand> MessageCommand::decode(Bytes parameters) noexcept {
    auto word = parameter_word(parameters);
    if (!word) return Unexpected(word.error());
    switch (*word & variant_mask) {
        case variant_read:
            if (auto c = MessageRead::decode(parameters)) return MessageCommand{*c};
            break;
        case variant_clear:
            if (auto c = MessageClear::decode(parameters)) return MessageCommand{*c};
            break;
        case variant_fal:
            if (auto c = FalFalsRead::decode(parameters)) return MessageCommand{*c};
            break;
        default:
            break;
    }
    return end_code(EndCode::parameter_error);
}

}  // namespace fins
