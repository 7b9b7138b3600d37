// CYCLE TIME READ 06 20 (W342 5-3-18; frames 6/0620). Same command-type shape as
// fins/commands/memory_area.hpp. (06 01 CPU UNIT STATUS READ is in diagnostics.hpp.)
//
//   06 20 00  initialize: the maximum and minimum restart; response: end code only
//   06 20 01  read: average of the last 8 cycles, maximum, minimum; 4-byte binary
//             each, in 0.1 ms units (5-3-18 example: 00 00 02 8A = 65.0 ms)
// Any other parameter byte answers 110C. Refused in PROGRAM mode (5-1-2: 2203).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

enum class CycleTimeOperation : std::uint8_t { initialize = 0x00, read = 0x01 };

// Cycle times in units of 0.1 ms.
struct CycleTimes {
    std::uint32_t average = 0;  // sum of the last 8 cycle times / 8
    std::uint32_t maximum = 0;  // since initialize / start of operation
    std::uint32_t minimum = 0;
    friend bool operator==(const CycleTimes&, const CycleTimes&) = default;
};

struct CycleTimeReadResponse {
    std::optional<CycleTimes> times;  // present for CycleTimeOperation::read only
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const CycleTimeReadResponse&, const CycleTimeReadResponse&) = default;
};

struct CycleTimeRead {
    static constexpr CommandCode code{0x06, 0x20};
    static constexpr std::string_view name = "CYCLE TIME READ";
    using Response = CycleTimeReadResponse;

    CycleTimeOperation operation = CycleTimeOperation::read;

    void encode(ByteWriter& w) const noexcept;
    // Exactly 1 byte: none 1002, more 1001, a value other than 00/01 110C.
    static Result<CycleTimeRead> decode(Bytes parameters) noexcept;
    // initialize: no data; read: exactly 12 bytes.
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
