// SectionChunks (contract in storage_chunks.hpp).
#include "plc/storage/storage_chunks.hpp"

#include <algorithm>

#include "plc/storage/storage_format.hpp"
#include "plc/storage/storage_os.hpp"

namespace fins::plc {

std::uint64_t round_up_to_page(std::uint64_t n) noexcept {
    constexpr auto page = state_file::page;
    return (std::max<std::uint64_t>(n, 1) + page - 1) / page * page;
}

SectionChunks::~SectionChunks() {
    for (auto [p, n] : mappings_)
        state_file::os::release_zeroed(p, n);
}

void* SectionChunks::reserve(std::size_t length) {
    void* p = state_file::os::reserve_zeroed(length);
    if (p == nullptr) return nullptr;
    mappings_.emplace_back(p, length);
    return p;
}

std::span<std::byte> SectionChunks::allocate(std::size_t bytes) {
    if (bytes >= lazy_section_bytes) {
        if (void* p = reserve(round_up_to_page(bytes))) return {static_cast<std::byte*>(p), bytes};
    } else {
        const std::size_t size = (std::max<std::size_t>(bytes, 1) + 15) / 16 * 16;
        if (chunk_left_ < size) {
            chunk_left_ = 0;
            if (void* p = reserve(chunk_bytes)) {
                chunk_next_ = static_cast<std::byte*>(p);
                chunk_left_ = chunk_bytes;
            }
        }
        if (chunk_left_ >= size) {
            std::byte* p = chunk_next_;
            chunk_next_ += size;
            chunk_left_ -= size;
            return {p, bytes};
        }
    }
    heap_.emplace_back((bytes + 7) / 8 + 1, 0);
    return {reinterpret_cast<std::byte*>(heap_.back().data()), bytes};
}

}  // namespace fins::plc
