// 23 01 FORCED SET/RESET and 23 02 FORCED SET/RESET CANCEL (W342 5-3-44, 5-3-45).
// Refused in RUN mode (2206) and under network write protection by the command table.
//
// 23 01 checks every item before changing anything (all or nothing):
//   110C  a set/reset designation other than 0000, 0001, 8000, 8001, FFFF
//   1101  an area code other than 30, 31, 32, 09 (CV 00, 01) or one this model lacks
//   1103  a word beyond the area, or a bit above 0F (00 for completion flags)
// then applies them in order: 0000/0001 force OFF/ON; 8000/8001 write OFF/ON and
// release (only the state changes for a bit that was not forced, 5-3-44 note); FFFF
// release keeping the state. Zero items: normal completion, nothing changes.
// Forced status shows through 70-72 / F0-F2 / 49 reads (plc::IoMemory).
#include <array>

#include "fins/commands/forced.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

namespace {

void apply(plc::IoMemory& memory, const plc::ElementRange& target, ForceAction action) noexcept {
    const bool flag = target.kind != ElementKind::bit;
    const auto force = [&](bool on) {
        if (flag)
            memory.force_completion_flag(target.index, on);
        else
            memory.force_bit(target.region, target.index, target.bit, on);
    };
    const auto release = [&] {
        if (flag)
            memory.release_completion_flag(target.index);
        else
            memory.release_bit(target.region, target.index, target.bit);
    };
    switch (action) {
        case ForceAction::force_off:
            force(false);
            break;
        case ForceAction::force_on:
            force(true);
            break;
        case ForceAction::release_off:
            force(false);
            release();
            break;
        case ForceAction::release_on:
            force(true);
            release();
            break;
        case ForceAction::release:
            release();
            break;
    }
}

}  // namespace

EndCode execute(HandlerContext& context, const ForcedSetReset& command, ByteWriter&) {
    if (command.items.size() > max_forced_items) return EndCode::command_too_long;
    auto& memory = context.plc.memory();
    std::array<plc::ElementRange, max_forced_items> targets{};
    for (std::size_t i = 0; i < command.items.size(); ++i) {
        const auto& item = command.items[i];
        if (!is_force_action(static_cast<std::uint16_t>(item.action)))
            return EndCode::parameter_error;
        const auto target = memory.locate(item.address, 1, use_force, plc::Intent::write);
        if (!target) return to_end_code(target.error());
        targets[i] = *target;
    }
    for (std::size_t i = 0; i < command.items.size(); ++i)
        apply(memory, targets[i], command.items[i].action);
    return EndCode::normal_completion;
}

EndCode execute(HandlerContext& context, const ForcedSetResetCancel&, ByteWriter&) noexcept {
    context.plc.memory().release_all_forced();
    return EndCode::normal_completion;
}

namespace {

constexpr HandlerEntry forced_table[] = {
    entry<ForcedSetReset>(),
    entry<ForcedSetResetCancel>(),
};

}  // namespace

std::span<const HandlerEntry> forced_handlers() noexcept {
    return forced_table;
}

}  // namespace fins::server::handlers
