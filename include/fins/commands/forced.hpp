// FORCED SET/RESET 23 01 and FORCED SET/RESET CANCEL 23 02 (W342 5-3-44, 5-3-45,
// frames 6/2301). Same command-type shape as fins/commands/memory_area.hpp.
//
// 23 01 parameters: number of bits (2 bytes), then per bit the set/reset designation
// (2 bytes) and the bit address (area code + word + bit, 4 bytes). Areas: 30 CIO, 31
// WR, 32 HR, 09 T/C completion flags; CV mode 00 and 01.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "fins/memory_area.hpp"

namespace fins {

// Set/reset designations of 5-3-44. Any other value decodes (the enum holds all 16
// bits) and the server answers 110C.
enum class ForceAction : std::uint16_t {
    force_off = 0x0000,    // forced reset: OFF and forced
    force_on = 0x0001,     // forced set: ON and forced
    release_off = 0x8000,  // OFF and released
    release_on = 0x8001,   // ON and released
    release = 0xFFFF,      // released, state kept
};
bool is_force_action(std::uint16_t value) noexcept;

struct ForcedItem {
    ForceAction action = ForceAction::force_on;
    MemoryAddress address;
    friend bool operator==(const ForcedItem&, const ForcedItem&) = default;
};
inline constexpr std::size_t forced_item_size = 2 + memory_address_size;
// 2,000 parameter bytes hold the count word and 333 items (frames 1.1).
inline constexpr std::size_t max_forced_items = (max_parameter_size - 2) / forced_item_size;

struct ForcedSetReset {
    static constexpr CommandCode code{0x23, 0x01};
    static constexpr std::string_view name = "FORCED SET/RESET";
    using Response = EmptyResponse;

    std::vector<ForcedItem> items;

    void encode(ByteWriter& w) const noexcept;
    // 1002 shorter than the count word; 1003 when the bytes after it are not exactly
    // count x 6 (5-1-3 "elements/data don't match").
    static Result<ForcedSetReset> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

struct ForcedSetResetCancel {
    static constexpr CommandCode code{0x23, 0x02};
    static constexpr std::string_view name = "FORCED SET/RESET CANCEL";
    using Response = EmptyResponse;

    void encode(ByteWriter&) const noexcept {}
    static Result<ForcedSetResetCancel> decode(Bytes parameters) noexcept;  // 1001 if any
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
