// Dispatcher::handle: header checks, command lookup, execution conditions, handler,
// response frame (see dispatcher.hpp for the contract).
#include "server/dispatch/dispatcher.hpp"

#include <algorithm>

#include "fins/command_table.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"
#include "server/routing/router.hpp"
#include "server/serial/serial_ports.hpp"

namespace fins::server {

namespace {

constexpr std::size_t response_prefix_size = header_size + command_code_size + end_code_size;

// Is the frame for this node? DNA 00 or ours; DA1 00 (local), ours or FF (broadcast,
// answered like our own node); DA2 00 (the CPU Unit), E1 when the profile has a Loop
// Control Board (Inner Board), or any unit the profile mounts (the units 05 02 lists).
// A wrong network or node answers 0201, a unit that is not there 0202. A Serial Gateway
// port's unit address (W342 5-3-46 tables) is there when finsd serves that port.
EndCode check_destination(const NodeAddress& destination, const NodeAddress& self,
                          const plc::Profile& profile, const SerialPorts* serial) noexcept {
    if (destination.network != local_network && destination.network != self.network)
        return EndCode::destination_node_not_in_network;
    if (destination.node != 0x00 && destination.node != self.node &&
        destination.node != broadcast_node)
        return EndCode::destination_node_not_in_network;
    if (destination.unit == inner_board_unit && profile.loop_control)
        return EndCode::normal_completion;
    if (serial != nullptr && serial->port(destination.unit) != nullptr)
        return EndCode::normal_completion;
    if (destination.unit != cpu_unit && profile.unit(destination.unit) == nullptr)
        return EndCode::unit_missing;
    return EndCode::normal_completion;
}

// Which unit runs a command: 02 40 belongs to the Loop Control Board (seed 001); a CPU
// Bus Unit (10-1F) answers its own 05 01 CONTROLLER DATA READ (handlers/configuration.cpp,
// W421 7-3-2); every other command belongs to the CPU Unit. A command sent to a unit
// that does not run it is undefined there (0401), as a present unit answers. 28 03/04/05
// belong to a Serial Gateway port (W342 5-3-46 .. 5-3-48); the CPU Unit models no serial
// port of its own.
bool served_by(const plc::Profile& profile, const SerialPorts* serial, std::uint8_t unit,
               CommandCode command) noexcept {
    const bool board_command = command == CommandCode{0x02, 0x40};
    const bool gateway_command = command.main == 0x28;
    if (serial != nullptr && serial->port(unit) != nullptr) return gateway_command;
    if (gateway_command) return false;
    if (unit == cpu_unit) return !board_command;
    if (unit == inner_board_unit && profile.loop_control) return board_command;
    const bool bus_unit = unit >= 0x10 && unit <= 0x1F;
    return bus_unit && command == CommandCode{0x05, 0x01};
}

}  // namespace

Dispatcher::Dispatcher(plc::Plc& plc, NodeAddress self) noexcept : plc_(plc), self_(self) {}

void Dispatcher::attach(Router& router, std::size_t port) noexcept {
    router_ = &router;
    port_ = port;
}

std::size_t Dispatcher::handle(Bytes request, MutableBytes out, const RequestContext& context) {
    // Without a header and command code there is no SID to answer.
    if (request.size() < header_size + command_code_size) return 0;
    ByteReader reader(request);
    const Header header = read_header(reader);
    const CommandCode command{reader.u8(), reader.u8()};
    // In a plant, a frame for another node (command or answer) goes on to it.
    NodeAddress self = self_;
    bool deliverable = true;
    if (router_ != nullptr) {
        deliverable = router_->note_source(port_, header, context);
        const auto local = router_->local_address(port_, header.destination);
        if (!local) return router_->forward(port_, request, out, context);
        self = *local;
    }
    if (header.is_response()) return 0;
    const bool reply =
        deliverable && header.response_required() && out.size() >= response_prefix_size;

    Header response = response_header(header, self);
    if (header.destination.node == broadcast_node) response.source.node = self.node;

    // Bits 6/7 of every end code report the CPU Unit's non-fatal/fatal errors (W342
    // 5-1-3): 0040 is a normal completion on a CPU Unit with a battery error.
    // Read when the answer is built, so an ERROR CLEAR that removed the last error
    // already answers without the flag.
    bool cpu_reached = false;
    const auto answer = [&](EndCode code) -> std::size_t {
        if (!reply) return 0;
        const std::uint16_t flags = cpu_reached ? plc_.errors().end_code_flags() : 0;
        ByteWriter w(out);
        write_response_prefix(w, response, command, static_cast<std::uint16_t>(code) | flags);
        return w.overflowed() ? 0 : w.size();
    };

    // Host Link FINS conversion (W342 5-1-1): a frame for a PLC behind a gateway port.
    if (serial_ != nullptr && header.destination.network != local_network &&
        header.destination.network != self.network)
        if (SerialGatewayPort* port = serial_->host_link_port(header.destination.network))
            return handlers::relay_to_host_link(*port, request, header, self, out, context);

    if (const auto code = check_destination(header.destination, self, plc_.profile(), serial_);
        code != EndCode::normal_completion)
        return answer(code);

    plc_.scan_cycle().advance(context.now);
    cpu_reached = true;
    const auto decoded = decode_request(request);  // 1001 above 2,012 bytes
    if (!decoded) return answer(handlers::to_end_code(decoded.error()));

    const CommandInfo* info = find_command(command);
    const handlers::HandlerEntry* entry = handlers::find_handler(command);
    if (info == nullptr || entry == nullptr || !plc_.profile().supports(command) ||
        !served_by(plc_.profile(), serial_, header.destination.unit, command))
        return answer(EndCode::undefined_command);

    if (const auto code = handlers::check_execution_conditions(info->conditions, plc_,
                                                               header.source, context.link);
        code != EndCode::normal_completion)
        return answer(code);

    // The handler writes its data directly after the prefix, at most 1,998 bytes.
    const auto data_offset = std::min(out.size(), response_prefix_size);
    ByteWriter data(
        out.subspan(data_offset, std::min(out.size() - data_offset, max_response_data_size)));
    handlers::HandlerContext handler_context{plc_, header, context};
    handler_context.serial = serial_;
    handler_context.self = response.source;
    auto code = entry->function(handler_context, decoded->parameters, data);
    if (handler_context.deferred) return 0;
    if (data.overflowed()) code = EndCode::response_too_long;
    // A write is a command whose row network write protection refuses, or a write
    // variant of a shared code (09 20 MESSAGE CLEAR) its handler flagged.
    const bool is_write = !info->conditions.network_write_protected || handler_context.write;
    // W342 5-3-30: the CPU Unit logs every FINS write command it receives.
    if (is_write) plc_.write_access_log().record(header.source, command, code, context.now);
    // [storage] durability = "power": what a write command changed is on disk before
    // its answer; when that fails the answer says so.
    if (is_write && !plc_.storage().commit() && code == EndCode::normal_completion)
        code = EndCode::memory_error;
    if (code != EndCode::normal_completion && !handler_context.keep_data) return answer(code);

    const auto prefix = answer(code);
    return prefix == 0 ? 0 : prefix + data.size();
}

}  // namespace fins::server
