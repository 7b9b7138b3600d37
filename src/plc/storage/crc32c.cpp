#include "plc/storage/crc32c.hpp"

#include <array>

namespace fins::plc {

namespace {

constexpr std::uint32_t polynomial = 0x82F63B78;  // 0x1EDC6F41 bit-reversed

// Eight tables for slicing-by-8: table[k][b] is the CRC of byte b followed by k zeros.
constexpr std::array<std::array<std::uint32_t, 256>, 8> make_tables() {
    std::array<std::array<std::uint32_t, 256>, 8> t{};
    for (std::uint32_t b = 0; b < 256; ++b) {
        std::uint32_t c = b;
        for (int bit = 0; bit < 8; ++bit)
            c = (c & 1U) != 0 ? (c >> 1) ^ polynomial : c >> 1;
        t[0][b] = c;
    }
    for (std::size_t k = 1; k < 8; ++k)
        for (std::uint32_t b = 0; b < 256; ++b)
            t[k][b] = (t[k - 1][b] >> 8) ^ t[0][t[k - 1][b] & 0xFFU];
    return t;
}

constexpr auto tables = make_tables();

}  // namespace

std::uint32_t crc32c(std::span<const std::byte> bytes, std::uint32_t crc) noexcept {
    std::uint32_t c = ~crc;
    std::size_t i = 0;
    const auto at = [&](std::size_t k) { return static_cast<std::uint32_t>(bytes[i + k]); };
    for (; i + 8 <= bytes.size(); i += 8) {
        const std::uint32_t lo = c ^ (at(0) | at(1) << 8 | at(2) << 16 | at(3) << 24);
        c = tables[7][lo & 0xFFU] ^ tables[6][(lo >> 8) & 0xFFU] ^ tables[5][(lo >> 16) & 0xFFU] ^
            tables[4][lo >> 24] ^ tables[3][at(4)] ^ tables[2][at(5)] ^ tables[1][at(6)] ^
            tables[0][at(7)];
    }
    for (; i < bytes.size(); ++i)
        c = (c >> 8) ^ tables[0][(c ^ at(0)) & 0xFFU];
    return ~c;
}

}  // namespace fins::plc
