// 06 01 CPU UNIT STATUS READ (W342 5-3-17, frames 6/0601; NX: W596 2-2, frames 9).
//
// Status byte: bit 0 running = not PROGRAM mode and no fatal error (a FALS or other
// fatal error stops the user program while the mode stays); bit 1 flash writing and
// bit 7 standby are always 0 (nothing here writes flash or waits for remote I/O); bit 2
// = the profile's battery. Error words, error code and message come from ErrorState;
// "message yes/no" from Messages.
// NX profiles answer the W596 fixed values: only the run bit and the mode are real;
// fatal / non-fatal data are 0001 when any error of that class is present, 0000 if not;
// message bits, error code and battery bits 0; the message 16 spaces.
#include "fins/commands/diagnostics.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

namespace {

std::uint8_t mode_byte(plc::OperatingMode mode) noexcept {
    switch (mode) {
        case plc::OperatingMode::program:
            return mode_program;
        case plc::OperatingMode::monitor:
            return mode_monitor;
        case plc::OperatingMode::run:
            return mode_run;
    }
    return mode_program;
}

}  // namespace

EndCode execute(HandlerContext& context, const CpuUnitStatusRead&, ByteWriter& out) noexcept {
    const auto& plc = context.plc;
    const auto& errors = plc.errors();
    const bool running = plc.mode() != plc::OperatingMode::program && !errors.has_fatal();
    const std::uint8_t run_bit = running ? status_running : 0;
    out.u8(static_cast<std::uint8_t>(
        run_bit |
        (plc.profile().battery && !plc.profile().nx_fixed_values ? status_battery_present : 0)));
    out.u8(mode_byte(plc.mode()));
    if (plc.profile().nx_fixed_values) {
        out.u16(errors.has_fatal() ? 0x0001 : 0x0000);
        out.u16(errors.has_non_fatal() ? 0x0001 : 0x0000);
        out.u16(0);  // message yes/no
        out.u16(0);  // error code
        out.text({}, error_message_size);
        return EndCode::normal_completion;
    }
    out.u16(errors.fatal_word());
    out.u16(errors.non_fatal_word());
    out.u16(context.plc.messages().present());
    const plc::ActiveError* worst = errors.most_serious();
    out.u16(worst != nullptr ? worst->code : std::uint16_t{0});
    out.text(errors.status_message(), error_message_size);
    return EndCode::normal_completion;
}

namespace {

constexpr HandlerEntry cpu_status_table[] = {entry<CpuUnitStatusRead>()};

}  // namespace

std::span<const HandlerEntry> cpu_status_handlers() noexcept {
    return cpu_status_table;
}

}  // namespace fins::server::handlers
