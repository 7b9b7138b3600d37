// The memory of the sections that finsd.state does not hold (cleared ones, all of them
// without a data directory, and any a file could not map): anonymous mappings the kernel
// backs lazily with zero pages, so a plant of 10,000 CPU Units pays only for the pages its
// clients touch (issues 10 and 19; docs/benchmarks.md). Large sections (EM banks, DM) get
// a mapping each; the small ones (about 28 per CPU Unit, 67 KB in all for a CJ2H) are
// packed into shared chunks, where zeroed heap blocks made each resident. Part of
// Storage (storage.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace fins::plc {

// `n` rounded up to whole pages (at least one).
std::uint64_t round_up_to_page(std::uint64_t n) noexcept;

class SectionChunks {
  public:
    // Sections from this size on get a mapping of their own.
    static constexpr std::size_t lazy_section_bytes = 16 * 1024;
    // The chunk the smaller sections are packed into; a CJ2H's fit in one.
    static constexpr std::size_t chunk_bytes = 128 * 1024;

    SectionChunks() = default;
    ~SectionChunks();
    SectionChunks(const SectionChunks&) = delete;
    SectionChunks& operator=(const SectionChunks&) = delete;

    // `bytes` of zeroed memory, 8-byte aligned (enough for every stored type), valid for
    // the life of this object. Never fails: without a mapping, zeroed heap memory
    // (resident, but correct).
    std::span<std::byte> allocate(std::size_t bytes);

  private:
    // Anonymous memory the kernel backs lazily with zero pages (nullptr: refused).
    void* reserve(std::size_t length);

    std::vector<std::pair<void*, std::size_t>> mappings_;
    std::byte* chunk_next_ = nullptr;  // the free rest of the last chunk
    std::size_t chunk_left_ = 0;
    std::vector<std::vector<std::uint64_t>> heap_;  // when no mapping was to be had
};

}  // namespace fins::plc
