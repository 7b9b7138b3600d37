// Private helpers shared by the command codecs (src/codec/commands/*.cpp): the error
// values every decoder returns, the answer with no data, and the fixed-length check of
// W342 5-1-3 (1002 command too short, 1001 command too long).
#pragma once

#include <cstddef>
#include <system_error>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"

namespace fins::codec {

// A request decoder's failure: the end code the PLC answers.
inline Unexpected end_code(EndCode e) {
    return Unexpected(make_error_code(e));
}

// A response decoder's failure: the answer does not fit the request.
inline Unexpected malformed() {
    return Unexpected(make_error_code(ClientError::malformed_response));
}

// The answer of a command whose response has no data after the end code.
inline Result<EmptyResponse> empty_response(Bytes data) {
    if (!data.empty()) return malformed();
    return EmptyResponse{};
}

// 1002 below `size` parameter bytes, 1001 above, else no error.
inline std::error_code check_fixed(Bytes parameters, std::size_t size) noexcept {
    if (parameters.size() < size) return make_error_code(EndCode::command_too_short);
    if (parameters.size() > size) return make_error_code(EndCode::command_too_long);
    return {};
}

}  // namespace fins::codec
