// 02 xx parameter area access: PARAMETER AREA READ/WRITE/CLEAR (W342 5-3-7 .. 5-3-9),
// and 02 40 READ MULTIPLE ITEMS FROM FUNCTION BLOCK of a Loop Control Board (seed 001).
// Validation lives in plc::ParameterAreas and plc::LoopControl; these functions apply
// the operating mode to I/O table access and build the responses.
#include "fins/commands/parameter_area.hpp"
#include "fins/commands/loop_control.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

EndCode execute(HandlerContext& context, const ParameterAreaRead& command,
                ByteWriter& out) noexcept;
EndCode execute(HandlerContext& context, const ParameterAreaWrite& command,
                ByteWriter& out) noexcept;
EndCode execute(HandlerContext& context, const ParameterAreaClear& command,
                ByteWriter& out) noexcept;

namespace {

// 5-3-8 / 5-3-9: "Data can be written to [cleared from] the I/O table only when the
// CPU Unit is in PROGRAM mode." The mode codes of 5-1-3 say which mode refused it.
EndCode io_table_mode(const plc::ParameterRange& range, plc::OperatingMode mode) noexcept {
    return range.io_table ? program_mode_only(mode) : EndCode::normal_completion;
}

}  // namespace

// W342 5-3-7. The answer echoes area and beginning word; the count field holds the
// words returned, bit 15 when the area's last word is among them. Data also goes out
// with 1104 (cut at the end) and 110B (cut at 498 words).
EndCode execute(HandlerContext& context, const ParameterAreaRead& command,
                ByteWriter& out) noexcept {
    const auto& parameters = context.plc.parameters();
    const auto plan = parameters.plan_read(command);
    if (!plan) return to_end_code(plan.error());
    const auto& range = plan->range;
    out.u16(command.area);
    out.u16(command.start);
    out.u16(static_cast<std::uint16_t>(range.count | (range.includes_last ? last_word_bit : 0)));
    parameters.read(range, out);
    context.keep_data = plan->code != EndCode::normal_completion;
    return plan->code;
}

// W342 5-3-8.
EndCode execute(HandlerContext& context, const ParameterAreaWrite& command, ByteWriter&) noexcept {
    auto& parameters = context.plc.parameters();
    const auto range = parameters.plan_write(command);
    if (!range) return to_end_code(range.error());
    if (const auto code = io_table_mode(*range, context.plc.mode());
        code != EndCode::normal_completion)
        return code;
    return parameters.write(*range, command.data);
}

// W342 5-3-9.
EndCode execute(HandlerContext& context, const ParameterAreaClear& command, ByteWriter&) noexcept {
    auto& parameters = context.plc.parameters();
    const auto range = parameters.plan_clear(command);
    if (!range) return to_end_code(range.error());
    if (const auto code = io_table_mode(*range, context.plc.mode());
        code != EndCode::normal_completion)
        return code;
    parameters.clear(*range);
    return EndCode::normal_completion;
}

namespace {

// Seed 001. Without a Loop Control Board the CPU Unit does not know 02 40 at all, so
// 0401 comes before any check of the command's shape. Then: 1001/1002/1003 (codec),
// 1101 block out of range or not registered, 110C no ITEMs, 1103 no ITEM readable,
// 110B read data section over 968 bytes. ITEMs that cannot be read are left out;
// "When one or more ITEMs has been read correctly, this shall be regarded as a normal
// completion". No allocation beyond the decoded address list.
EndCode function_block_item_read(HandlerContext& context, Bytes parameters, ByteWriter& out) {
    if (!context.plc.loop_control().present()) return EndCode::undefined_command;
    const auto command = FunctionBlockItemRead::decode(parameters);
    if (!command) return to_end_code(command.error());
    const auto* block = plc::LoopControl::find_block(command->block);
    if (block == nullptr) return EndCode::area_classification_missing;
    if (command->items.empty()) return EndCode::parameter_error;

    const auto count = out.reserve(2);
    std::size_t section = 0;
    std::uint16_t read = 0;
    for (const auto item : command->items) {
        const auto value = context.plc.loop_control().read_item(*block, item);
        if (!value) continue;
        section += std::size_t{3} + value->length;  // address, length, data
        if (section > max_item_read_data) return EndCode::response_too_long;
        out.u16(item);
        out.u8(value->length);
        out.bytes(Bytes(value->bytes.data(), value->length));
        ++read;
    }
    if (read == 0) return EndCode::address_range_error;
    if (count.size() == 2) {
        count[0] = static_cast<std::uint8_t>(read >> 8);
        count[1] = static_cast<std::uint8_t>(read);
    }
    return EndCode::normal_completion;
}

constexpr HandlerEntry parameter_area_table[] = {
    entry<ParameterAreaRead>(),
    entry<ParameterAreaWrite>(),
    entry<ParameterAreaClear>(),
    HandlerEntry{FunctionBlockItemRead::code, &function_block_item_read},
};

}  // namespace

std::span<const HandlerEntry> parameter_area_handlers() noexcept {
    return parameter_area_table;
}

}  // namespace fins::server::handlers
