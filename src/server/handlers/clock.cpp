// 07 xx time data access: CLOCK READ 07 01, CLOCK WRITE 07 02 (W342 5-3-19, 5-3-20).
//
// The clock model (plc/clock.hpp) is host local time plus a retained offset. The codec
// has answered 1002/1001 for lengths and 110C for a byte that is not BCD; the model
// answers 110C for a field out of range. CLOCK WRITE needs the access right (3001) and
// is refused under network write protection (2102), both by the dispatcher.
#include "fins/commands/clock.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

// W342 5-3-19.
EndCode execute(HandlerContext& context, const ClockRead&, ByteWriter& out) noexcept {
    ClockReadResponse{context.plc.clock().read(context.request.now)}.encode(out);
    return EndCode::normal_completion;
}

// W342 5-3-20. Nothing changes unless every field is in range.
EndCode execute(HandlerContext& context, const ClockWrite& command, ByteWriter&) noexcept {
    return context.plc.clock().write(command, context.request.now);
}

namespace {
constexpr HandlerEntry table[] = {entry<ClockRead>(), entry<ClockWrite>()};
}  // namespace

std::span<const HandlerEntry> clock_handlers() noexcept {
    return table;
}

}  // namespace fins::server::handlers
