// ACCESS RIGHT ACQUIRE / FORCED ACQUIRE / RELEASE, 0C 01 .. 0C 03 (W342 5-3-24 ..
// 5-3-26, frames 6/0C01). Same command-type shape as fins/commands/memory_area.hpp.
//
// Every variant carries the program number, always FFFF; a server answers 1106
// (program missing) for any other value. When another device holds the access right,
// 0C 01 answers 3001 followed by the holder (AccessRightHolder). The typed client
// send<AccessRightAcquire>() reports that as EndCode::no_access_right; read the holder
// with send_raw() and AccessRightHolder::decode().
#pragma once

#include <cstdint>
#include <string_view>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

inline constexpr std::uint16_t any_program = 0xFFFF;  // "Always FFFF (hex)"

// The 3 bytes after end code 3001: unit address, node address, network address, in
// that order (W342 p.202 diagram labels and Wireshark agree; libfins reads it reversed,
// frames 10 item 2).
struct AccessRightHolder {
    NodeAddress holder;
    static constexpr std::size_t size = 3;
    void encode(ByteWriter& w) const noexcept;
    // Exactly 3 bytes, else malformed_response.
    static Result<AccessRightHolder> decode(Bytes data);
    friend bool operator==(const AccessRightHolder&, const AccessRightHolder&) = default;
};

struct AccessRightAcquire {
    static constexpr CommandCode code{0x0C, 0x01};
    static constexpr std::string_view name = "ACCESS RIGHT ACQUIRE";
    using Response = EmptyResponse;

    std::uint16_t program_number = any_program;

    void encode(ByteWriter& w) const noexcept;
    // 1002 shorter than 2 bytes, 1001 longer.
    static Result<AccessRightAcquire> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

struct AccessRightForcedAcquire {
    static constexpr CommandCode code{0x0C, 0x02};
    static constexpr std::string_view name = "ACCESS RIGHT FORCED ACQUIRE";
    using Response = EmptyResponse;

    std::uint16_t program_number = any_program;

    void encode(ByteWriter& w) const noexcept;
    static Result<AccessRightForcedAcquire> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

struct AccessRightRelease {
    static constexpr CommandCode code{0x0C, 0x03};
    static constexpr std::string_view name = "ACCESS RIGHT RELEASE";
    using Response = EmptyResponse;

    std::uint16_t program_number = any_program;

    void encode(ByteWriter& w) const noexcept;
    static Result<AccessRightRelease> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
