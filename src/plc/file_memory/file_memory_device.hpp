// Private to plc::FileMemory's source files: an open file device, and the error a
// Result-returning operation gives for an end code.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "plc/file_memory/file_memory.hpp"

namespace fins::plc {

struct FileMemory::Device {
    int fd = -1;  // kept open in device_fds_
    std::size_t index = 0;
    std::uint64_t capacity = 0;
    std::string_view label;
};

inline Unexpected fail(EndCode code) {
    return Unexpected(make_error_code(code));
}

}  // namespace fins::plc
