// Dispatcher::handle: the stages of a request in order (length, route, destination,
// command, execution conditions, handler; see dispatcher.hpp for the contract).
#include "server/dispatch/dispatcher.hpp"
#include "server/scenario/fault_hook.hpp"

#include <algorithm>

#include "fins/command_table.hpp"
#include "plc/plc.hpp"
#include "server/dispatch/relay_error.hpp"
#include "server/handlers/handlers.hpp"
#include "server/metrics/metrics.hpp"
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

Dispatcher::Destination Dispatcher::find_destination(const Header& header) const noexcept {
    // Host Link FINS conversion (W342 5-1-1): the network of the PLCs behind one of this
    // node's gateway ports is reached through that port (with routing tables, the table
    // names that network for the serial port).
    const auto network = header.destination.network;
    if (serial_ != nullptr && network != local_network && network != self_.network)
        if (SerialGatewayPort* port = serial_->host_link_port(network))
            return {Route::host_link, self_, port};
    // In a plant the router decides whether the frame is for this CPU Unit (any of its
    // ports) and as which address it answers.
    if (router_ != nullptr) {
        const auto local = router_->local_address(port_, header.destination);
        if (!local) return {Route::router, self_, nullptr};
        return {Route::this_node, *local, nullptr};
    }
    return {Route::this_node, self_, nullptr};
}

std::size_t Dispatcher::handle(Bytes request, MutableBytes out, const RequestContext& context) {
    // Without a header and command code there is no SID to answer.
    if (request.size() < header_size + command_code_size) return 0;
    metrics::start_request();
    ByteReader reader(request);
    const Header header = read_header(reader);
    const CommandCode command{reader.u8(), reader.u8()};
    // In a plant the arrival port learns where the source's answers go (router.hpp).
    const bool deliverable = router_ == nullptr || router_->note_source(port_, header, context);
    const Destination to = find_destination(header);

    // 1. Length, before any route: nothing past this point (a router's or the Host Link
    //    relay's copy of the frame, the codec) sees more than a FINS frame (W596 1-2).
    if (request.size() > max_frame_size)
        return refuse_too_long(header, command, to, deliverable, out);

    // 2. Destination: a frame for another node goes on, command or answer (a plant's
    //    router, the Host Link relay); on this node, the unit must be there (0201, 0202).
    if (to.route == Route::router) return router_->forward(port_, request, out, context);
    if (to.route == Route::host_link)
        return handlers::relay_to_host_link(*to.host_link, request, header, to.self, out, context);
    if (header.is_response()) return 0;
    // A scenario's unit faults: switched off, or this answer dropped (fault_hook.hpp).
    if (faults_ != nullptr && faults_->silent()) return 0;

    Reply reply{plc_, header, command, to.self, deliverable, out};
    if (const auto code = check_destination(header.destination, to.self, plc_.profile(), serial_);
        code != EndCode::normal_completion)
        return reply.answer(code);

    // 3. Command: its parameters (the codec's 10xx, 11xx) and who serves it (0401).
    plc_.power_on(context.now);  // a Plc no server started (tests): powers up now
    reply.cpu_reached = true;
    const auto decoded = decode_request(request);
    if (!decoded) return reply.answer(handlers::to_end_code(decoded.error()));

    const CommandInfo* info = find_command(command);
    const handlers::HandlerEntry* entry = handlers::find_handler(command);
    if (info == nullptr || entry == nullptr || !plc_.profile().supports(command) ||
        !served_by(plc_.profile(), serial_, header.destination.unit, command))
        return reply.answer(EndCode::undefined_command);

    // 4. Execution conditions (W342 5-1-2).
    if (const auto code = handlers::check_execution_conditions(info->conditions, plc_,
                                                               header.source, context.link);
        code != EndCode::normal_completion)
        return reply.answer(code);

    // 5. The command's handler, and the answer now or later.
    if (faults_ != nullptr)
        return run_with_faults(reply, *info, *entry, decoded->parameters, context);
    return run(reply, *info, *entry, decoded->parameters, context);
}

namespace {

// The 4-byte I/O memory address at `at` of `parameters` (W342 5-2-1); false past the end.
bool address_at(Bytes parameters, std::size_t at, MemoryAddress& address) noexcept {
    if (parameters.size() < at + memory_address_size) return false;
    address.area_code = parameters[at];
    address.word = static_cast<std::uint16_t>(parameters[at + 1] << 8 | parameters[at + 2]);
    address.bit = parameters[at + 3];
    return true;
}

// A scenario's end code for the memory area command `sub` (01 01-01 05) when any address
// it names is in a faulted area: the start of 01 01/02/03, each element of 01 04, the
// source and the destination of 01 05. 0: none.
std::uint16_t memory_area_fault(const FaultHook& faults, std::uint8_t sub,
                                Bytes parameters) noexcept {
    MemoryAddress address;
    std::uint16_t code = 0;
    switch (sub) {
        case 0x01:
        case 0x02:
        case 0x03:
            if (address_at(parameters, 0, address)) code = faults.area_end_code(address);
            break;
        case 0x04:
            for (std::size_t at = 0; code == 0 && address_at(parameters, at, address);
                 at += memory_address_size)
                code = faults.area_end_code(address);
            break;
        case 0x05:
            if (address_at(parameters, 0, address)) code = faults.area_end_code(address);
            if (code == 0 && address_at(parameters, memory_address_size, address))
                code = faults.area_end_code(address);
            break;
        default:
            break;
    }
    return code;
}

}  // namespace

// A scenario's end code for an area (memory_area_fault) and its latency (the answer
// leaves through the session's deferred path).
std::size_t Dispatcher::run_with_faults(Reply& reply, const CommandInfo& info,
                                        const handlers::HandlerEntry& entry, Bytes parameters,
                                        const RequestContext& context) {
    if (reply.command.main == 0x01)
        if (const auto code = memory_area_fault(*faults_, reply.command.sub, parameters); code != 0)
            return reply.answer(static_cast<EndCode>(code));
    const std::size_t n = run(reply, info, entry, parameters, context);
    if (n == 0 || faults_->latency().count() <= 0 || context.reply_path == nullptr) return n;
    faults_->send_later(Bytes(reply.out.data(), n), context.reply_path->defer());
    return 0;
}

Dispatcher::Reply::Reply(plc::Plc& cpu_unit, const Header& request, CommandCode command_code,
                         const NodeAddress& self, bool deliverable,
                         MutableBytes out_buffer) noexcept
    : plc(cpu_unit),
      header(request),
      response(response_header(request, self)),
      command(command_code),
      wanted(deliverable && request.response_required() &&
             out_buffer.size() >= response_prefix_size),
      out(out_buffer) {
    if (request.destination.node == broadcast_node) response.source.node = self.node;
}

std::size_t Dispatcher::Reply::answer(EndCode code) const noexcept {
    metrics::note_request(command, code);
    if (!wanted) return 0;
    // Bits 6/7 of every end code report the CPU Unit's non-fatal/fatal errors (W342
    // 5-1-3): 0040 is a normal completion on a CPU Unit with a battery error. Read when
    // the answer is built, so an ERROR CLEAR that removed the last error already answers
    // without the flag.
    const std::uint16_t flags = cpu_reached ? plc.errors().end_code_flags() : 0;
    ByteWriter w(out);
    write_response_prefix(w, response, command, static_cast<std::uint16_t>(code) | flags);
    return w.overflowed() ? 0 : w.size();
}

std::size_t Dispatcher::refuse_too_long(const Header& header, CommandCode command,
                                        const Destination& to, bool deliverable,
                                        MutableBytes out) noexcept {
    // An answer too long to be a FINS frame is not passed on (there is no one to tell).
    if (header.is_response()) return 0;
    // W342 5-1-3 1001 "Command too long", answered by the unit that received the frame:
    // for another node (a router, the Host Link relay) it is a relay error naming this
    // node, as every fault that stops a frame on its way (router.hpp); for this node, the
    // plain end code (the frame never reached the CPU Unit: no error flags).
    if (to.route != Route::this_node)
        return write_relay_error(header, command, self_, EndCode::command_too_long, out);
    Reply reply{plc_, header, command, to.self, deliverable, out};
    return reply.answer(EndCode::command_too_long);
}

std::size_t Dispatcher::run(Reply& reply, const CommandInfo& info,
                            const handlers::HandlerEntry& entry, Bytes parameters,
                            const RequestContext& context) {
    const MutableBytes out = reply.out;
    // The handler writes its data directly after the prefix, at most 1,998 bytes.
    const auto data_offset = std::min(out.size(), response_prefix_size);
    ByteWriter data(
        out.subspan(data_offset, std::min(out.size() - data_offset, max_response_data_size)));
    handlers::HandlerContext handler_context{plc_, reply.header, context};
    handler_context.serial = serial_;
    handler_context.self = reply.response.source;
    auto code = entry.function(handler_context, parameters, data);
    if (handler_context.deferred) return 0;
    if (data.overflowed()) code = EndCode::response_too_long;
    // A write is a command whose row network write protection refuses, or a write
    // variant of a shared code (09 20 MESSAGE CLEAR) its handler flagged.
    const bool is_write = !info.conditions.network_write_protected || handler_context.write;
    // W342 5-3-30: the CPU Unit logs every FINS write command it receives.
    if (is_write)
        plc_.write_access_log().record(reply.header.source, reply.command, code, context.now);
    // [storage] durability = "power": what a write command changed is on disk before
    // its answer; when that fails the answer says so.
    if (is_write && !plc_.storage().commit() && code == EndCode::normal_completion)
        code = EndCode::memory_error;
    if (code != EndCode::normal_completion && !handler_context.keep_data) return reply.answer(code);

    const auto prefix = reply.answer(code);
    return prefix == 0 ? 0 : prefix + data.size();
}

}  // namespace fins::server
