// Helpers for the 22 xx handler tests: typed commands sent as full request frames.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <fmt/core.h>

#include "fins/commands/file_memory.hpp"
#include "server/frame_builder.hpp"

namespace fins::test {

inline FileName file(std::string_view text) {
    return *FileName::from(text);
}

inline std::vector<std::uint8_t> text_bytes(std::string_view s) {
    return {s.begin(), s.end()};
}

// Encodes `command` and sends it with its command code through the harness.
template <class C>
Reply run(Harness& h, const C& command, const FrameFields& fields = {}) {
    std::vector<std::uint8_t> params(max_parameter_size);
    ByteWriter w(params);
    command.encode(w);
    params.resize(w.size());
    return h.send(fmt::format("{:04X} ", C::code.value()) + to_hex(params), fields);
}

}  // namespace fins::test
