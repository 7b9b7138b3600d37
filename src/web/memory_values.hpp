// Typed reads and writes of a CPU Unit's I/O memory for the HTTP API and the WebSocket,
// with the `fins` CLI's address strings and value formats (typed/value_format.hpp) and its
// rules: a bit address (D100.03, CIO10.13, TK2) reads and writes bits; a word address with
// as=bits reads T/C completion flags (T5); IR0-15 are 32-bit elements; ascii (string)
// reads `count` words as one text.
//
// The model is read and written directly (IoMemory::locate/read/write: the 5-2-2 table,
// forced bits kept, 2101 on read-only words), as a Programming Device does, not as a FINS
// node: no write access log record and no network write protection. Pure: no I/O.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>
#include <tl/expected.hpp>

#include "fins/address.hpp"
#include "typed/value_format.hpp"

namespace fins::plc {
class Plc;
class IoMemory;
}  // namespace fins::plc

namespace fins::web {

// An answer other than 200: the HTTP status and a sentence for {"error": ...}.
struct ApiError {
    unsigned status = 400;
    std::string message;
};
template <class T>
using ApiResult = tl::expected<T, ApiError>;

// Values one read may return: a page shows a window of an area, never all of it.
inline constexpr std::size_t max_values_per_read = 4096;

// A checked (address, count, format): what to read, resolved once for a subscription.
struct ValueQuery {
    std::string address_text;  // as given
    std::string as;            // as given ("uint16" when absent)
    Address start;
    typed::Format format = typed::Format::uint16;
    std::size_t count = 1;     // values
    bool bits = false;         // bit elements (flags count as bits)
    bool wide = false;         // IR: 32-bit elements
    std::size_t elements = 0;  // elements on the wire (words, bits or registers)
    MemoryAddress memory{};    // the wire address of the first element
};

// Checks the address, format and count against the model (400 with the reason, the
// FINS end code's message when the model refuses the range).
ApiResult<ValueQuery> make_query(const plc::IoMemory& memory, std::string_view address,
                                 std::size_t count, std::string_view as);

// The elements' bytes now, in the 5-2-1 encodings (a subscription compares them first).
ApiResult<void> read_raw(const plc::IoMemory& memory, const ValueQuery& query,
                         std::chrono::system_clock::time_point now, std::vector<std::uint8_t>& raw);
// Those bytes as values (400 when a word is not BCD for as=bcd).
ApiResult<nlohmann::json> decode_values(const ValueQuery& query,
                                        const std::vector<std::uint8_t>& raw);

// The values now: numbers (strings for hex, NaN/Infinity, ascii), 0/1 for bits.
ApiResult<nlohmann::json> read_values(const plc::IoMemory& memory, const ValueQuery& query,
                                      std::chrono::system_clock::time_point now);

// Writes `values` (a JSON array of numbers, strings or booleans; a string for ascii) from
// `address`. 400 for a bad value or a range the model refuses (read-only: 2101).
ApiResult<std::size_t> write_values(plc::IoMemory& memory, std::string_view address,
                                    const nlohmann::json& values, std::string_view as);

}  // namespace fins::web
