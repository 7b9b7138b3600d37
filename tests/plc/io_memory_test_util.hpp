// Shared helpers for the IoMemory tests.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "plc/io_memory.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc::test {

// Owns the heap Storage an IoMemory takes its regions from (base-from-member: the
// Storage is constructed first).
struct HeapStorage {
    Storage storage;
};
class HeapMemory : private HeapStorage, public IoMemory {
  public:
    explicit HeapMemory(Profile profile) : HeapStorage{}, IoMemory(std::move(profile), storage) {}
};

// 0 on success, else the FINS end code a locate() failed with.
inline std::uint16_t code_of(const Result<ElementRange>& r) {
    return r ? std::uint16_t{0} : static_cast<std::uint16_t>(r.error().value());
}

inline MemoryAddress at(std::uint8_t code, std::uint16_t word, std::uint8_t bit = 0) {
    return MemoryAddress{code, word, bit};
}

// Reads through locate() + read() as 01 04 may (every code is listed for it).
inline std::vector<std::uint8_t> read(const IoMemory& m, MemoryAddress a, std::uint32_t count,
                                      TimePoint now = {}) {
    const auto r = m.locate(a, count, use_multi_read, Intent::read);
    if (!r) return {0xEE};
    std::vector<std::uint8_t> out(r->byte_size() + 8);
    ByteWriter w(out);
    m.read(*r, w, now);
    out.resize(w.size());
    return out;
}

inline std::uint16_t write(IoMemory& m, MemoryAddress a, std::uint32_t count,
                           const std::vector<std::uint8_t>& data) {
    const auto r = m.locate(a, count, use_write, Intent::write);
    if (!r) return code_of(r);
    return static_cast<std::uint16_t>(m.write(*r, data));
}

using Bytes8 = std::vector<std::uint8_t>;

}  // namespace fins::plc::test
