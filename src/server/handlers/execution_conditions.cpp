// The execution conditions of W342 5-1-2, evaluated generically from the row of the
// command table before any handler runs.
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

EndCode check_execution_conditions(const ExecutionConditions& conditions, const plc::Plc& plc,
                                   const NodeAddress& source, Link link) noexcept {
    switch (plc.mode()) {
        case plc::OperatingMode::run:
            if (!conditions.run) return EndCode::wrong_mode_run;
            break;
        case plc::OperatingMode::monitor:
            if (!conditions.monitor) return EndCode::wrong_mode_monitor;
            break;
        case plc::OperatingMode::program:
            if (!conditions.program) return EndCode::wrong_mode_program;
            break;
    }
    // W342 5-1-2 note 5: the protection applies to commands sent "via networks"; a
    // local (in-process) request is not one. Whether `source` is refused depends on the
    // mode (all nodes, listed nodes, all but the listed nodes: plc/plc.hpp).
    if (via_network(link) && !conditions.network_write_protected &&
        plc.network_write_protected_from(source))
        return EndCode::write_protected;
    if (plc.access_right_held_by_other(source) && !conditions.access_right_elsewhere)
        return EndCode::no_access_right;
    if (plc.um_read_protection() && !conditions.um_read_protected) return EndCode::read_protected;
    if (plc.dip_write_protection() && !conditions.dip_write_protected) return EndCode::read_only;
    return EndCode::normal_completion;
}

EndCode program_mode_only(plc::OperatingMode mode) noexcept {
    switch (mode) {
        case plc::OperatingMode::run:
            return EndCode::wrong_mode_run;
        case plc::OperatingMode::monitor:
            return EndCode::wrong_mode_monitor;
        case plc::OperatingMode::program:
            break;
    }
    return EndCode::normal_completion;
}

}  // namespace fins::server::handlers
