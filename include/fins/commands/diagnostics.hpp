// CPU UNIT STATUS READ 06 01 (W342 5-3-17) and the three commands sharing 09 20:
// MESSAGE READ, MESSAGE CLEAR, FAL/FALS READ (5-3-21 .. 5-3-23). Same command-type
// shape as fins/commands/memory_area.hpp.
//
// 09 20 variants are told apart by bits 15-14 of the parameter word (frames 6/0920):
// 00 read (bits 0-7 select MSG 0-7), 01 clear (bits 0-7), 10 FAL/FALS read (bits 13-0
// = number). A server decodes the word once through MessageCommand.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// ---- 06 01 ----

// Status byte (5-3-17 "Status"); bits 3-6 are undefined and masked by readers.
inline constexpr std::uint8_t status_running = 0x01;
inline constexpr std::uint8_t status_flash_writing = 0x02;
inline constexpr std::uint8_t status_battery_present = 0x04;
inline constexpr std::uint8_t status_standby = 0x80;

// Mode byte (5-3-17 "Mode").
inline constexpr std::uint8_t mode_program = 0x00;
inline constexpr std::uint8_t mode_monitor = 0x02;
inline constexpr std::uint8_t mode_run = 0x04;

// Bit numbers of the fatal error word (frames 6/0601, FieldServer and libfins agree).
namespace fatal_bit {
inline constexpr unsigned memory = 15, io_bus = 14, duplication = 13, inner_board = 12,
                          io_points_overflow = 11, io_setting = 10, program = 9,
                          cycle_time_over = 8, fals = 6;
}
// Bit numbers of the non-fatal error word (frames 6/0601; bits 1-0 unconfirmed, unused).
namespace non_fatal_bit {
inline constexpr unsigned fal = 15, duplex = 14, interrupt_task = 13, basic_io = 12, plc_setup = 10,
                          io_verification = 9, inner_board = 8, cpu_bus_unit = 7,
                          special_io_unit = 6, sysmac_bus = 5, battery = 4,
                          cpu_bus_unit_setting = 3, special_io_unit_setting = 2;
}

inline constexpr std::size_t error_message_size = 16;  // FAL/FALS message (5-3-17, 5-3-23)
inline constexpr std::size_t cpu_status_size = 26;     // response data after the end code

struct CpuUnitStatusReadResponse {
    std::uint8_t status = 0;
    std::uint8_t mode = mode_program;
    std::uint16_t fatal_errors = 0;      // fatal_bit::*
    std::uint16_t non_fatal_errors = 0;  // non_fatal_bit::*
    std::uint16_t messages = 0;          // bit k: MSG k registered (bits 8-15 zero)
    std::uint16_t error_code = 0;        // most serious current error, 0000 if none
    std::string error_message = std::string(error_message_size, ' ');  // exactly 16 bytes

    [[nodiscard]] bool running() const noexcept { return (status & status_running) != 0; }
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const CpuUnitStatusReadResponse&,
                           const CpuUnitStatusReadResponse&) = default;
};

struct CpuUnitStatusRead {
    static constexpr CommandCode code{0x06, 0x01};
    static constexpr std::string_view name = "CPU UNIT STATUS READ";
    using Response = CpuUnitStatusReadResponse;

    void encode(ByteWriter&) const noexcept {}
    // No parameters: 1001 when any are present.
    static Result<CpuUnitStatusRead> decode(Bytes parameters) noexcept;
    // Exactly 26 bytes.
    Result<Response> decode_response(Bytes data) const;
};

// ---- 09 20 ----

inline constexpr std::size_t msg_count = 8;       // MSG 0-7 (5-3-21)
inline constexpr std::size_t msg_text_size = 32;  // 32 ASCII bytes per message
inline constexpr std::uint16_t message_clear_bit = 0x4000;
inline constexpr std::uint16_t fal_read_bit = 0x8000;
inline constexpr std::uint16_t fal_number_mask = 0x3FFF;
// FAL(006)/FALS(007) numbers 001-511 (error codes 4101-42FF / C101-C2FF, 5-3-27).
inline constexpr std::uint16_t max_fal_number = 511;

struct MessageReadResponse {
    std::uint8_t messages = 0;       // the bits of the messages returned
    std::vector<std::string> texts;  // one per set bit, ascending, exactly 32 bytes each
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const MessageReadResponse&, const MessageReadResponse&) = default;
};

struct MessageRead {
    static constexpr CommandCode code{0x09, 0x20};
    static constexpr std::string_view name = "MESSAGE READ";
    using Response = MessageReadResponse;

    std::uint8_t messages = 0;  // bit k: read MSG k

    void encode(ByteWriter& w) const noexcept;
    // 1002/1001 unless exactly 2 bytes; 110C when bits 15-14 are not 00 or 13-8 not 0.
    static Result<MessageRead> decode(Bytes parameters) noexcept;
    // The echoed word must name only MSG bits; 32 bytes per bit set.
    Result<Response> decode_response(Bytes data) const;
};

struct MessageClear {
    static constexpr CommandCode code{0x09, 0x20};
    static constexpr std::string_view name = "MESSAGE CLEAR";
    using Response = EmptyResponse;

    std::uint8_t messages = 0;  // bit k: clear MSG k

    void encode(ByteWriter& w) const noexcept;
    // 1002/1001 unless exactly 2 bytes; 110C when bits 15-14 are not 01 or 13-8 not 0.
    static Result<MessageClear> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

struct FalFalsReadResponse {
    std::uint16_t number = 0;                                    // bits 13-0 of the echo
    std::string message = std::string(error_message_size, ' ');  // exactly 16 bytes
    // The answer echoes the command word, bit 15 included (frames 6/0920 "same layout").
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const FalFalsReadResponse&, const FalFalsReadResponse&) = default;
};

struct FalFalsRead {
    static constexpr CommandCode code{0x09, 0x20};
    static constexpr std::string_view name = "FAL/FALS READ";
    using Response = FalFalsReadResponse;

    std::uint16_t number = 0;  // FAL/FALS number, 1-511

    void encode(ByteWriter& w) const noexcept;
    // 1002/1001 unless exactly 2 bytes; 110C when bits 15-14 are not 10. The number's
    // range is the handler's to check.
    static Result<FalFalsRead> decode(Bytes parameters) noexcept;
    // 18 bytes whose number matches the request.
    Result<Response> decode_response(Bytes data) const;
};

// Server side: whichever of the three the parameter word selects.
struct MessageCommand {
    static constexpr CommandCode code{0x09, 0x20};
    static constexpr std::string_view name = "MESSAGE READ/CLEAR";

    std::variant<MessageRead, MessageClear, FalFalsRead> command;

    // 1002/1001 unless exactly 2 bytes; 110C for bits 15-14 = 11 or stray bits 13-8 on
    // read/clear.
    static Result<MessageCommand> decode(Bytes parameters) noexcept;
};

}  // namespace fins
