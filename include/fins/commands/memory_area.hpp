// I/O memory area access commands, 01 01 .. 01 05 (W342 5-3-2 .. 5-3-6).
//
// Every command type follows one shape, which the client's send<C>() and the server's
// dispatch table rely on:
//   static constexpr CommandCode code;  static constexpr std::string_view name;
//   using Response = ...;
//   void encode(ByteWriter&) const;                      parameters after MRC SRC
//   static Result<C> decode(Bytes parameters);            errors are FINS EndCodes
//   Result<Response> decode_response(Bytes data) const;   data after the end code;
//                                                         errors are ClientError
//   (Response) void encode(ByteWriter&) const;            response data after the end code
// Decoded requests hold views into the caller's buffer (no copies); responses own
// their data because they outlive the receive buffer.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "fins/memory_area.hpp"

namespace fins {

// Element limits over Ethernet / Controller Link (W342 5-2-2 "Number of Elements").
inline constexpr std::uint16_t max_read_words = 999;
inline constexpr std::uint16_t max_write_words = 997;
// W342 5-3-5: 167 elements per MULTIPLE MEMORY AREA READ over Ethernet / Controller Link.
inline constexpr std::size_t max_multiple_read_elements = 167;

struct EmptyResponse {
    void encode(ByteWriter&) const noexcept {}
    friend bool operator==(const EmptyResponse&, const EmptyResponse&) = default;
};

struct MemoryAreaReadResponse {
    std::vector<std::uint8_t> data;  // count x element size bytes, as on the wire
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const MemoryAreaReadResponse&, const MemoryAreaReadResponse&) = default;
};

struct MemoryAreaRead {
    static constexpr CommandCode code{0x01, 0x01};
    static constexpr std::string_view name = "MEMORY AREA READ";
    using Response = MemoryAreaReadResponse;

    MemoryAddress start;
    std::uint16_t count = 0;

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 6 bytes, 1001 when longer.
    static Result<MemoryAreaRead> decode(Bytes parameters) noexcept;
    // Expects exactly count x element_size(start.area_code) bytes.
    Result<Response> decode_response(Bytes data) const;
};

struct MemoryAreaWrite {
    static constexpr CommandCode code{0x01, 0x02};
    static constexpr std::string_view name = "MEMORY AREA WRITE";
    using Response = EmptyResponse;

    MemoryAddress start;
    std::uint16_t count = 0;
    Bytes data;  // count x element size bytes; a view, the caller keeps it alive

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 6 bytes. The data length is checked against the count by
    // the handler (it needs the area's element size; unknown areas answer 1101 first).
    static Result<MemoryAreaWrite> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

struct MemoryAreaFill {
    static constexpr CommandCode code{0x01, 0x03};
    static constexpr std::string_view name = "MEMORY AREA FILL";
    using Response = EmptyResponse;

    MemoryAddress start;
    std::uint16_t count = 0;
    std::uint16_t value = 0;

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 8 bytes, 1001 when longer.
    static Result<MemoryAreaFill> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

struct MultipleMemoryAreaReadResponse {
    struct Item {
        std::uint8_t area_code = 0;
        std::uint32_t value = 0;  // the element's 1, 2 or 4 bytes, big-endian
        friend bool operator==(const Item&, const Item&) = default;
    };
    std::vector<Item> items;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const MultipleMemoryAreaReadResponse&,
                           const MultipleMemoryAreaReadResponse&) = default;
};

struct MultipleMemoryAreaRead {
    static constexpr CommandCode code{0x01, 0x04};
    static constexpr std::string_view name = "MULTIPLE MEMORY AREA READ";
    using Response = MultipleMemoryAreaReadResponse;

    std::vector<MemoryAddress> items;

    void encode(ByteWriter& w) const noexcept;
    // Empty parameters are valid (normal response, nothing read). 1002 when the length
    // is not a multiple of 4; 1001 for more than 167 elements.
    static Result<MultipleMemoryAreaRead> decode(Bytes parameters);
    // Each item echoes its area code followed by element_size(code) bytes.
    Result<Response> decode_response(Bytes data) const;
};

struct MemoryAreaTransfer {
    static constexpr CommandCode code{0x01, 0x05};
    static constexpr std::string_view name = "MEMORY AREA TRANSFER";
    using Response = EmptyResponse;

    MemoryAddress source;
    MemoryAddress destination;
    std::uint16_t count = 0;

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 10 bytes, 1001 when longer.
    static Result<MemoryAreaTransfer> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
