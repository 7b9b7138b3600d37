// 28 03 CONVERT TO COMPOWAY/F, 28 04 CONVERT TO MODBUS-RTU, 28 05 CONVERT TO MODBUS-ASCII
// (W342 5-3-46 .. 5-3-48): the port at the destination unit address frames the command
// for its line and answers later with the slave's reply (server/serial/serial_gateway_port.hpp,
// docs/architecture.md "Deferred answers").
#include <array>

#include "fins/commands/serial_gateway.hpp"
#include "fins/modbus.hpp"
#include "server/handlers/handlers.hpp"
#include "server/serial/serial_ports.hpp"

namespace fins::server::handlers {

namespace {

// Hands a framed request to the port at the destination unit address; the answer goes
// back through the session that received the request.
EndCode submit(HandlerContext& context, CommandCode code, SerialFraming framing, Bytes frame,
               bool expect_answer) {
    SerialGatewayPort* port =
        context.serial != nullptr ? context.serial->port(context.header.destination.unit) : nullptr;
    if (port == nullptr) return EndCode::undefined_command;  // the dispatcher checked already
    // A session that cannot answer later (the local control channel): the port is busy
    // for it.
    if (context.request.reply_path == nullptr) return EndCode::destination_node_busy;
    Completion reply;
    if (context.header.response_required()) reply = context.request.reply_path->defer();
    const Header response = response_header(context.header, context.self);
    port->submit(framing, frame, expect_answer,
                 [reply = std::move(reply), response, code](EndCode end, Bytes payload) {
                     if (!reply) return;
                     std::array<std::uint8_t, max_frame_size> out{};
                     ByteWriter w(out);
                     write_response_prefix(w, response, code, static_cast<std::uint16_t>(end));
                     if (end == EndCode::normal_completion) w.bytes(payload);
                     if (w.overflowed()) {
                         // A slave answer longer than a FINS response can carry.
                         w = ByteWriter(out);
                         write_response_prefix(
                             w, response, code,
                             static_cast<std::uint16_t>(EndCode::response_too_long));
                     }
                     reply(Bytes{out.data(), w.size()});
                 });
    context.deferred = true;
    return EndCode::normal_completion;
}

}  // namespace

EndCode execute(HandlerContext& context, const ConvertToCompowayF& command, ByteWriter&) {
    std::array<std::uint8_t, SerialGatewayPort::max_frame> frame{};
    ByteWriter w(frame);
    std::array<std::uint8_t, max_parameter_size> body{};
    ByteWriter b(body);
    command.encode(b);
    compoway_f::write_frame(w, Bytes{body.data(), b.size()});
    if (w.overflowed()) return EndCode::command_too_long;
    return submit(context, command.code, SerialFraming::compoway_f, Bytes{frame.data(), w.size()},
                  !command.broadcast());
}

EndCode execute(HandlerContext& context, const ConvertToModbusRtu& command, ByteWriter&) {
    std::array<std::uint8_t, modbus::max_rtu_frame> pdu{};
    ByteWriter p(pdu);
    command.encode(p);
    std::array<std::uint8_t, modbus::max_rtu_frame> frame{};
    ByteWriter w(frame);
    modbus::write_rtu_frame(w, Bytes{pdu.data(), p.size()});
    if (p.overflowed() || w.overflowed()) return EndCode::command_too_long;
    return submit(context, command.code, SerialFraming::modbus_rtu, Bytes{frame.data(), w.size()},
                  !command.broadcast());
}

EndCode execute(HandlerContext& context, const ConvertToModbusAscii& command, ByteWriter&) {
    std::array<std::uint8_t, modbus::max_ascii_frame> frame{};
    ByteWriter w(frame);
    if (!modbus::write_ascii_frame(w, command.ascii)) return EndCode::parameter_error;
    if (w.overflowed()) return EndCode::command_too_long;
    return submit(context, command.code, SerialFraming::modbus_ascii, Bytes{frame.data(), w.size()},
                  !command.broadcast());
}

namespace {
constexpr HandlerEntry table[] = {
    entry<ConvertToCompowayF>(),
    entry<ConvertToModbusRtu>(),
    entry<ConvertToModbusAscii>(),
};
}  // namespace

std::span<const HandlerEntry> serial_gateway_handlers() noexcept {
    return table;
}

}  // namespace fins::server::handlers
