// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), the checksum of the state
// file's header blocks and retained sections (storage.cpp). Plain table-driven code:
// it runs over a few MB at start and at a clean stop only, never per request.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace fins::plc {

// Continues `crc` (0 for a new checksum) over `bytes`. crc32c("123456789") == 0xE3069283.
[[nodiscard]] std::uint32_t crc32c(std::span<const std::byte> bytes,
                                   std::uint32_t crc = 0) noexcept;

}  // namespace fins::plc
