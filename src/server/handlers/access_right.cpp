// 0C 01 ACCESS RIGHT ACQUIRE, 0C 02 ACCESS RIGHT FORCED ACQUIRE, 0C 03 ACCESS RIGHT
// RELEASE (W342 5-3-24 .. 5-3-26, frames 6/0C01).
//
// The holder is the request header's source address (network, node, unit). Every
// variant needs program number FFFF (1106 otherwise, 5-1-3 "FFFF hex was not
// specified"), checked before anything changes.
// - 0C 01: acquires when nobody or the requester holds the right; held by another
//   device: 3001 followed by the holder (unit, node, network: AccessRightHolder).
// - 0C 02: always acquires; the previous holder is not told (5-3-25).
// - 0C 03: releases whoever holds it; normal also when nobody does (5-3-26).
// Once held, the commands marked Disabled in 5-1-2's access-right column answer 3001 to
// every other device (check_execution_conditions) and 09 20 MESSAGE CLEAR does so in
// messages.cpp.
#include "fins/commands/access_right.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

EndCode execute(HandlerContext& context, const AccessRightAcquire& command,
                ByteWriter& out) noexcept {
    if (command.program_number != any_program) return EndCode::program_missing;
    const NodeAddress& requester = context.header.source;
    if (context.plc.access_right_held_by_other(requester)) {
        // The dispatcher sends this data after the 3001 end code.
        AccessRightHolder{*context.plc.access_right_holder()}.encode(out);
        context.keep_data = true;
        return EndCode::no_access_right;
    }
    context.plc.set_access_right_holder(requester);
    return EndCode::normal_completion;
}

EndCode execute(HandlerContext& context, const AccessRightForcedAcquire& command,
                ByteWriter&) noexcept {
    if (command.program_number != any_program) return EndCode::program_missing;
    context.plc.set_access_right_holder(context.header.source);
    return EndCode::normal_completion;
}

EndCode execute(HandlerContext& context, const AccessRightRelease& command, ByteWriter&) noexcept {
    if (command.program_number != any_program) return EndCode::program_missing;
    context.plc.set_access_right_holder(std::nullopt);
    return EndCode::normal_completion;
}

namespace {

constexpr HandlerEntry access_right_table[] = {
    entry<AccessRightAcquire>(),
    entry<AccessRightForcedAcquire>(),
    entry<AccessRightRelease>(),
};

}  // namespace

std::span<const HandlerEntry> access_right_handlers() noexcept {
    return access_right_table;
}

}  // namespace fins::server::handlers
