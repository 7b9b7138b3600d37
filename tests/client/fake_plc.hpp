// A tiny FINS responder for the client tests: DM and CIO words and bits, 01 01 .. 01 05.
// Pure (no I/O): the in-test UDP and TCP servers call handle() for each request frame.
// Deliberately independent of src/server, so client tests do not depend on it.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/frame.hpp"

namespace fins::test {

class FakePlc {
  public:
    // The response frame, or an empty vector when nothing is to be answered (the
    // no-response ICF bit, or not a request at all).
    std::vector<std::uint8_t> handle(Bytes request);

    NodeAddress self{0, 1, 0};
    std::array<std::uint16_t, 32768> dm{};
    std::array<std::uint16_t, 6144> cio{};
    // A read or write whose first word is this answers 1103 (address range error).
    std::optional<std::uint16_t> fail_word;
    // ORed into every normal end code (e.g. 0x0040, non-fatal CPU error).
    std::uint16_t end_code_flags = 0;

  private:
    std::vector<std::uint8_t> execute(Bytes request);
    std::uint16_t* word(std::uint8_t area_code, std::uint32_t index);
    std::uint16_t read_element(std::uint8_t area_code, std::uint32_t word, std::uint8_t bit,
                               bool& ok);
};

// Builds a response frame to `request` with `end_code` and `data` (for raw answers).
std::vector<std::uint8_t> make_response(Bytes request, NodeAddress responder,
                                        std::uint16_t end_code, Bytes data = {});

}  // namespace fins::test
