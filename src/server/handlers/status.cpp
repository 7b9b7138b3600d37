// 06 xx status reading: CYCLE TIME READ 06 20 (W342 5-3-18). (06 01 CPU UNIT STATUS
// READ is registered by its own group file.)
//
// The dispatcher refuses 06 20 in PROGRAM mode (5-1-2: 2203); the scan cycle has run
// since power-on and is read at the request's time; the codec has answered 1002/1001 and
// 110C for a parameter other than 00/01.
#include "fins/commands/status.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

// W342 5-3-18. 00: the maximum and minimum restart (end code only); 01: average of the
// last 8 cycles, maximum, minimum in 0.1 ms.
EndCode execute(HandlerContext& context, const CycleTimeRead& command, ByteWriter& out) noexcept {
    auto& cycle = context.plc.scan_cycle();
    if (command.operation == CycleTimeOperation::initialize) {
        cycle.initialize(context.request.now);
        return EndCode::normal_completion;
    }
    CycleTimeReadResponse{cycle.times(context.request.now)}.encode(out);
    return EndCode::normal_completion;
}

namespace {
constexpr HandlerEntry table[] = {entry<CycleTimeRead>()};
}  // namespace

std::span<const HandlerEntry> status_handlers() noexcept {
    return table;
}

}  // namespace fins::server::handlers
