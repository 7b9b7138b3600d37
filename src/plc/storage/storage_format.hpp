// The layout of finsd's state file and Storage's error codes (storage.cpp).
//
// One header page, then each retained section on its own page-aligned run, in the
// order the models asked for them. The header page holds two blocks, each with its own
// CRC-32C, each written in one piece so that a check failure means damage, not an
// interrupted update:
//
//   [0, 3584)     descriptor: magic, version, "complete", profile, file size and the
//                 section table. Written only while the file is built under its
//                 temporary name, so it reaches `finsd.state` whole (rename).
//   [3584, 4096)  seal block, one 512-byte sector: the "stopped cleanly" flag and each
//                 section's CRC-32C. Cleared (flag 0) and synced when finsd starts
//                 serving, written (flag 1) and synced after the sections at a clean
//                 stop. A device writes a sector whole, so it is never half old.
//
// Integers are in the host's byte order: a state file moves between hosts of the same
// endianness only (the magic's version check refuses nothing else).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <system_error>

#include "fins/error.hpp"
#include "plc/storage/crc32c.hpp"
#include "plc/storage/storage_os.hpp"

namespace fins::plc::state_file {

inline constexpr std::array<char, 8> magic{'F', 'I', 'N', 'S', 'K', 'I', 'T', '\0'};
// 1: no checksums, created in place; the same descriptor layout with 0 for its crc and
// a zero seal block (convert_version1).
inline constexpr std::uint32_t version = 2;
inline constexpr std::size_t page = 4096;
inline constexpr std::size_t seal_offset = 3584;
inline constexpr std::size_t name_size = 40;
inline constexpr std::size_t profile_size = 64;
inline constexpr std::size_t max_entries = 54;
inline constexpr std::uint32_t complete_mark = 1;
inline constexpr std::uint32_t clean_mark = 1;

struct Entry {
    char name[name_size];  // NUL-terminated
    std::uint64_t offset;
    std::uint64_t size;
    std::uint64_t reserved;
};

struct Descriptor {
    std::array<char, 8> magic;
    std::uint32_t version;
    std::uint32_t complete;  // complete_mark: every section of the profile is present
    char profile[profile_size];
    std::uint64_t file_size;
    std::uint32_t count;
    std::uint32_t crc;  // CRC-32C of the descriptor with this field 0
    Entry entries[max_entries];
};
static_assert(sizeof(Descriptor) <= seal_offset);

struct Seal {
    std::uint32_t clean;  // clean_mark: stopped cleanly, section_crc holds
    std::uint32_t crc;    // CRC-32C of the seal block with this field 0
    std::uint32_t section_crc[max_entries];
};
static_assert(sizeof(Seal) <= page - seal_offset);

struct Header {
    Descriptor descriptor;
    std::byte pad[seal_offset - sizeof(Descriptor)];
    Seal seal;
    std::byte tail[page - seal_offset - sizeof(Seal)];
};
static_assert(sizeof(Header) == page);

enum class Error : int {
    not_a_state_file = 1,
    unsupported_version,
    other_profile,
    damaged,
    layout_mismatch,
    in_use,
    too_many_sections,
    duplicate_section,
    profile_id_too_long,
    empty,
    incomplete,
    header_checksum,
    section_checksum,
    no_space,
};

std::error_code make_error(Error e) noexcept;

// CRC-32C of `block` with its own checksum field `field` taken as 0.
template <class Block>
std::uint32_t crc_without(const Block& block, const std::uint32_t& field) {
    const auto all = std::as_bytes(std::span(&block, 1));
    const auto at =
        static_cast<std::size_t>(reinterpret_cast<const std::byte*>(&field) - all.data());
    constexpr std::array<std::byte, sizeof field> zero{};
    return crc32c(all.subspan(at + sizeof field), crc32c(zero, crc32c(all.first(at))));
}

// A complete version 1 `finsd.state` (open as `fd`, `size` bytes, in the locked
// directory `dir`) copied to a version 2 file: built as finsd.state.new (reserved,
// header given version 2, its checksum and a "not stopped cleanly" seal), synced, the
// old file kept as finsd.state.version1 (a hard link), renamed into place, directory
// synced. Returns the new file's descriptor. An incomplete version 1 file, or one with
// more sections than version 2 holds, is refused (incomplete, unsupported_version).
Result<os::Handle> convert_version1(const os::Directory& dir, os::Handle fd, std::uint64_t size);
// A cleanly stopped file's sections (open as `fd`, `size` bytes, `header` its header)
// against the seal's checksums: section_checksum when one differs.
Result<void> verify_section_checksums(os::Handle fd, std::uint64_t size, const Header& header);
// True for the errors about an existing file's content (Storage::is_refusal).
bool is_refusal(const std::error_code& e) noexcept;

}  // namespace fins::plc::state_file
