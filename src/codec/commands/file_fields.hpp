// Private helpers of the 22 xx codecs (file_memory.cpp, file_transfer.cpp): the fields
// the file commands share (a 12-byte file name, a length-prefixed directory path) and the
// end of a decode.
#pragma once

#include <string>
#include <string_view>
#include <utility>

#include "codec/command_codec.hpp"
#include "fins/byte_io.hpp"
#include "fins/commands/file_memory.hpp"
#include "fins/error.hpp"

namespace fins::codec::file_fields {

// Reads the fields through `r`; a short input leaves r truncated (1002), extra bytes
// leave r not at its end (1001).
inline std::error_code finish(const ByteReader& r) noexcept {
    if (r.truncated()) return make_error_code(EndCode::command_too_short);
    if (r.remaining() != 0) return make_error_code(EndCode::command_too_long);
    return {};
}

inline FileName read_name(ByteReader& r) noexcept {
    FileName n;
    const auto b = r.bytes(n.bytes.size());
    for (std::size_t i = 0; i < b.size(); ++i)
        n.bytes[i] = b[i];
    return n;
}

inline void write_name(ByteWriter& w, const FileName& n) noexcept {
    w.bytes(n.bytes);
}

inline std::string read_path(ByteReader& r) {
    const auto length = r.u16();
    const auto b = r.bytes(length);
    return std::string(b.begin(), b.end());
}

inline void write_path(ByteWriter& w, std::string_view path) noexcept {
    w.u16(static_cast<std::uint16_t>(path.size()));
    for (const char c : path)
        w.u8(static_cast<std::uint8_t>(c));
}

// The decoded command, or the end code finish() gives.
template <class C>
Result<C> checked(C command, const ByteReader& r) {
    if (auto ec = finish(r)) return Unexpected(ec);
    return command;
}

}  // namespace fins::codec::file_fields
