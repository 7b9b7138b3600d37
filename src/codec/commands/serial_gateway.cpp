// 28 03 / 28 04 / 28 05 Serial Gateway bodies (W342 5-3-46 .. 5-3-48; see
// fins/commands/serial_gateway.hpp for the layouts).
#include "fins/commands/serial_gateway.hpp"

#include "codec/command_codec.hpp"
#include "fins/modbus.hpp"

namespace fins {

using codec::end_code;
using codec::malformed;

void ConvertToCompowayF::encode(ByteWriter& w) const noexcept {
    compoway_f::encode_command(w, command);
}

Result<ConvertToCompowayF> ConvertToCompowayF::decode(Bytes parameters) noexcept {
    const auto command = compoway_f::decode_command(parameters);
    if (!command) return end_code(EndCode::command_too_short);
    return ConvertToCompowayF{*command};
}

Result<SerialGatewayResponse> ConvertToCompowayF::decode_response(Bytes data) const {
    if (!data.empty() && !compoway_f::decode_response(data)) return malformed();
    return SerialGatewayResponse{{data.begin(), data.end()}};
}

void ConvertToModbusRtu::encode(ByteWriter& w) const noexcept {
    w.u8(slave);
    w.u8(function);
    w.bytes(data);
}

Result<ConvertToModbusRtu> ConvertToModbusRtu::decode(Bytes parameters) noexcept {
    if (parameters.size() < 2) return end_code(EndCode::command_too_short);
    if (parameters.size() > max_pdu) return end_code(EndCode::command_too_long);
    return ConvertToModbusRtu{parameters[0], parameters[1], parameters.subspan(2)};
}

Result<SerialGatewayResponse> ConvertToModbusRtu::decode_response(Bytes answer) const {
    if (answer.size() == 1) return malformed();
    return SerialGatewayResponse{{answer.begin(), answer.end()}};
}

bool ConvertToModbusAscii::broadcast() const noexcept {
    return ascii.size() >= 2 && ascii[0] == '0' && ascii[1] == '0';
}

Result<ConvertToModbusAscii> ConvertToModbusAscii::decode(Bytes parameters) noexcept {
    if (parameters.size() < 4) return end_code(EndCode::command_too_short);
    if (parameters.size() > max_ascii) return end_code(EndCode::command_too_long);
    std::array<std::uint8_t, max_ascii / 2> binary{};
    if (!modbus::hex_decode(parameters, binary)) return end_code(EndCode::parameter_error);
    return ConvertToModbusAscii{parameters};
}

Result<SerialGatewayResponse> ConvertToModbusAscii::decode_response(Bytes data) const {
    std::array<std::uint8_t, max_ascii / 2> binary{};
    if (!data.empty() &&
        (data.size() < 4 || data.size() > max_ascii || !modbus::hex_decode(data, binary)))
        return malformed();
    return SerialGatewayResponse{{data.begin(), data.end()}};
}

}  // namespace fins
