// 04 xx operating mode changes: RUN 04 01, STOP 04 02 (W342 5-3-13, 5-3-14).
//
// The codec has already answered the parameter errors (1002/1001 lengths, 1106 program
// number other than FFFF, 110C mode byte other than 02/04); the dispatcher the
// execution conditions (access right 3001, network write protection 2102). Both are
// accepted in every mode, and a change to the mode the CPU Unit is already in is a
// normal completion (5-3-13/5-3-14 "Comments").
//
// The scan cycle follows the mode: leaving PROGRAM starts operation (statistics
// restart, 5-3-18 "Comments"); entering PROGRAM stops it. RUN <-> MONITOR keeps the
// program running. A fatal CPU error is not modelled here (the error model decides
// whether operation may start; see docs/commands.md "Operating mode, CPU Unit
// data, cycle time and clock").
#include "fins/commands/operating_mode.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

namespace {

void change_mode(HandlerContext& context, plc::OperatingMode mode) noexcept {
    context.plc.change_mode(mode, context.request.now);
}

}  // namespace

// W342 5-3-13. Command code only, or code + FFFF: MONITOR.
EndCode execute(HandlerContext& context, const Run& command, ByteWriter&) noexcept {
    change_mode(context, command.target() == RunMode::run ? plc::OperatingMode::run
                                                          : plc::OperatingMode::monitor);
    return EndCode::normal_completion;
}

// W342 5-3-14. Command code only, or code + FFFF: PROGRAM.
EndCode execute(HandlerContext& context, const Stop&, ByteWriter&) noexcept {
    change_mode(context, plc::OperatingMode::program);
    return EndCode::normal_completion;
}

namespace {
constexpr HandlerEntry table[] = {entry<Run>(), entry<Stop>()};
}  // namespace

std::span<const HandlerEntry> operating_mode_handlers() noexcept {
    return table;
}

}  // namespace fins::server::handlers
