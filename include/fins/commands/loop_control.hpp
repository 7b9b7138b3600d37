// 02 40 READ MULTIPLE ITEMS FROM FUNCTION BLOCK, the ITEM read of a CS-series Loop
// Control Board / Unit (seed 001, Loop Control manual 6-3; frames 8).
//
// Command:  function block address (2, 0000-03E7 = block 0-999), number of ITEMs (2),
//           then one read start address (ITEM number, 2) per ITEM.
// Response: number of ITEMs read normally (2), then per ITEM read: read start address
//           (2), data length in bytes (1), data.
// The board's own length rules count the command code: at most 2,002 bytes (1001),
// at least 6 bytes (1002); an address list that does not match the ITEM count is 1003.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// Seed 001: command length counted from MRC, 6 .. 2,002 bytes.
inline constexpr std::size_t max_loop_command_bytes = 2002;
inline constexpr std::size_t min_loop_command_bytes = 6;
// Seed 001: block addresses and ITEM numbers 0-999 (0000-03E7).
inline constexpr std::uint16_t max_function_block = 999;
inline constexpr std::uint16_t max_item_number = 999;
// Seed 001 110B: the read data section (every ITEM's address, length and data) may
// hold at most 968 bytes.
inline constexpr std::size_t max_item_read_data = 968;

struct FunctionBlockItemReadResponse {
    struct Item {
        std::uint16_t item = 0;          // read start address (ITEM number)
        std::vector<std::uint8_t> data;  // 1-255 bytes, as the board sends them
        friend bool operator==(const Item&, const Item&) = default;
    };
    std::vector<Item> items;  // the ITEMs read normally, in request order
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const FunctionBlockItemReadResponse&,
                           const FunctionBlockItemReadResponse&) = default;
};

struct FunctionBlockItemRead {
    static constexpr CommandCode code{0x02, 0x40};
    static constexpr std::string_view name = "READ MULTIPLE ITEMS FROM FUNCTION BLOCK";
    using Response = FunctionBlockItemReadResponse;

    std::uint16_t block = 0;           // function block address 0-999
    std::vector<std::uint16_t> items;  // read start addresses; the count is items.size()

    void encode(ByteWriter& w) const noexcept;
    // 1002 under 4 parameter bytes, 1001 over 2,000, 1003 when the address list does not
    // hold exactly the declared number of ITEMs (an odd trailing byte included). A count
    // of 0 decodes; the handler answers 110C for it.
    static Result<FunctionBlockItemRead> decode(Bytes parameters);
    // Each ITEM returned must be one requested, in request order; lengths must add up.
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
