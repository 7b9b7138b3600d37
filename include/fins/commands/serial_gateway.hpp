// Serial Gateway: 28 03 CONVERT TO COMPOWAY/F COMMAND, 28 04 CONVERT TO MODBUS-RTU
// COMMAND, 28 05 CONVERT TO MODBUS-ASCII COMMAND (W342 5-3-46 .. 5-3-48; frames 6/2803,
// 6/2804, 6/2805; frames-serial-files.md 2). Addressed to a serial port's unit address
// (80 + 4N / 81 + 4N on Serial Communications Unit N, E4 / E5 on the Board); the port
// adds the serial framing (STX ETX BCC, CRC-16, ':' LRC CR LF), sends it and answers
// with the slave's reply inside a normal (0000) FINS response.
//
// FINS bodies:
//   28 03 command:  node (2 ASCII) | sub-address (2 ASCII) | SID (1 ASCII) | MRC SRC (4 ASCII)
//                   | text (ASCII)
//         response: the slave's frame between STX and ETX: node | sub-address | end code
//                   [| MRC SRC | MRES SRES | text]  (no SID; frames-serial-files.md 2.3)
//   28 04 command:  slave address (1) | function code (1) | data (n); response the same
//                   layout from the slave (no CRC, frames-serial-files.md 2.2)
//   28 05 command:  slave address, function code and data as hex digits; response the
//                   same layout (no ':', LRC or CR LF)
// A broadcast (CompoWay/F node "XX", Modbus address 00) gets no slave answer: the port
// answers 0000 with no data once the frame is sent (W336 11-3-2).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/compoway_f.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// W342 5-3-46 .. 5-3-48 tables: the unit address (DA2) of a serial port. Serial
// Communications Unit N (0-F): port 1 = 80 + 4N, port 2 = 81 + 4N; the Board: E4, E5.
constexpr std::uint8_t scu_port_unit_address(unsigned unit_number, unsigned port) noexcept {
    return static_cast<std::uint8_t>(0x80U + 4U * unit_number + (port - 1U));
}
constexpr std::uint8_t board_port_unit_address(unsigned port) noexcept {
    return static_cast<std::uint8_t>(0xE4U + (port - 1U));
}

// 28 03/04/05 responses: the slave's answer as the FINS response carries it.
struct SerialGatewayResponse {
    std::vector<std::uint8_t> data;  // empty after a broadcast
    void encode(ByteWriter& w) const noexcept { w.bytes(data); }
    friend bool operator==(const SerialGatewayResponse&, const SerialGatewayResponse&) = default;
};

struct ConvertToCompowayF {
    static constexpr CommandCode code{0x28, 0x03};
    static constexpr std::string_view name = "CONVERT TO COMPOWAY/F COMMAND";
    using Response = SerialGatewayResponse;

    compoway_f::Command command;  // its text is a view, the caller keeps it alive

    [[nodiscard]] bool broadcast() const noexcept {
        return command.node == compoway_f::broadcast_node;
    }
    void encode(ByteWriter& w) const noexcept;
    // 1002 below node + sub-address + SID + MRC SRC (9 bytes).
    static Result<ConvertToCompowayF> decode(Bytes parameters) noexcept;
    // Empty, a 6-byte frame-error answer, or at least the 14-byte header.
    Result<Response> decode_response(Bytes data) const;
};

struct ConvertToModbusRtu {
    static constexpr CommandCode code{0x28, 0x04};
    static constexpr std::string_view name = "CONVERT TO MODBUS-RTU COMMAND";
    using Response = SerialGatewayResponse;
    // Modbus over Serial Line 2.5.1.1: 256-byte frames, of which the CRC takes 2.
    static constexpr std::size_t max_pdu = 254;

    std::uint8_t slave = 1;  // 00 = broadcast, 01-F7 a slave
    std::uint8_t function = 0;
    Bytes data;  // a view

    [[nodiscard]] bool broadcast() const noexcept { return slave == 0; }
    void encode(ByteWriter& w) const noexcept;
    // 1002 below address + function, 1001 above max_pdu bytes.
    static Result<ConvertToModbusRtu> decode(Bytes parameters) noexcept;
    // Empty or at least address + function.
    Result<Response> decode_response(Bytes answer) const;
};

struct ConvertToModbusAscii {
    static constexpr CommandCode code{0x28, 0x05};
    static constexpr std::string_view name = "CONVERT TO MODBUS-ASCII COMMAND";
    using Response = SerialGatewayResponse;
    // Modbus over Serial Line 2.5.2.1: 513 characters less ':', LRC, CR LF.
    static constexpr std::size_t max_ascii = 508;

    Bytes ascii;  // address, function, data as hex digits; a view

    // Address "00".
    [[nodiscard]] bool broadcast() const noexcept;
    void encode(ByteWriter& w) const noexcept { w.bytes(ascii); }
    // 1002 below 4 digits, 1001 above max_ascii; 110C for an odd count or a character
    // that is not a hex digit: the LRC cannot be computed (W342 5-3-48 is silent; the
    // choice is pinned in tests/codec/commands/serial_gateway_test.cpp).
    static Result<ConvertToModbusAscii> decode(Bytes parameters) noexcept;
    // Empty or at least 4 hex digits.
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
