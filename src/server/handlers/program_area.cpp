// 03 xx program area access: PROGRAM AREA READ/WRITE/CLEAR (W342 5-3-10 .. 5-3-12).
// Validation lives in plc::UserProgram; the dispatcher has already applied UM read
// protection (2002), DIP switch protection and the PROGRAM-mode rule (2206/2205).
#include "fins/commands/program_area.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

EndCode execute(HandlerContext& context, const ProgramAreaRead& command, ByteWriter& out) noexcept;
EndCode execute(HandlerContext& context, const ProgramAreaWrite& command, ByteWriter& out) noexcept;
EndCode execute(HandlerContext& context, const ProgramAreaClear& command, ByteWriter& out) noexcept;

namespace {

void write_echo(ByteWriter& out, std::uint16_t program_number, std::uint32_t address,
                std::uint16_t count, bool last) noexcept {
    out.u16(program_number);
    out.u32(address);
    out.u16(static_cast<std::uint16_t>(count | (last ? program_last_bit : 0)));
}

}  // namespace

// W342 5-3-10. The count field holds the bytes returned, bit 15 when the UM's last
// address is among them; bytes cut at the UM's end go out with 1104.
EndCode execute(HandlerContext& context, const ProgramAreaRead& command, ByteWriter& out) noexcept {
    const auto& program = context.plc.program();
    const auto plan = program.plan_read(command);
    if (!plan) return to_end_code(plan.error());
    const auto& range = plan->range;
    write_echo(out, command.program_number, range.address, range.count, range.includes_last);
    program.read(range, out);
    context.keep_data = plan->code != EndCode::normal_completion;
    return plan->code;
}

// W342 5-3-11. The response echoes program number, beginning address and number of
// bytes (bit 15 included) as sent.
EndCode execute(HandlerContext& context, const ProgramAreaWrite& command,
                ByteWriter& out) noexcept {
    auto& program = context.plc.program();
    const auto range = program.plan_write(command);
    if (!range) return to_end_code(range.error());
    program.write(*range, command.data, command.last);
    write_echo(out, command.program_number, command.address, command.count, command.last);
    return EndCode::normal_completion;
}

// W342 5-3-12. Clearing also clears the protection, UM read protection included.
EndCode execute(HandlerContext& context, const ProgramAreaClear& command, ByteWriter&) noexcept {
    auto& program = context.plc.program();
    if (const auto code = program.check_clear(command); code != EndCode::normal_completion)
        return code;
    program.clear(command.clear_code);
    context.plc.set_um_read_protection(false);
    return EndCode::normal_completion;
}

namespace {

constexpr HandlerEntry program_area_table[] = {
    entry<ProgramAreaRead>(),
    entry<ProgramAreaWrite>(),
    entry<ProgramAreaClear>(),
};

}  // namespace

std::span<const HandlerEntry> program_area_handlers() noexcept {
    return program_area_table;
}

}  // namespace fins::server::handlers
