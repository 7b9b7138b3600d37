// Test traffic into the fuzz corpus. With FINS_FUZZ_DUMP=DIR in the environment,
// dump_test_bytes("request", bytes) writes the bytes to DIR/request/<FNV-1a hash>; the
// test harnesses call it for every frame and stream they send, and fuzz/make_corpus.sh
// turns the dump into seeds. Without the variable it does nothing.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>

namespace fins::fuzz {

inline void dump_test_bytes(const char* kind, std::span<const std::uint8_t> bytes) {
    static const char* const dir = std::getenv("FINS_FUZZ_DUMP");
    if (dir == nullptr || bytes.empty()) return;
    std::uint64_t hash = 14695981039346656037ull;
    for (auto b : bytes)
        hash = (hash ^ b) * 1099511628211ull;
    const auto folder = std::filesystem::path(dir) / kind;
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    char name[17];
    static constexpr char digits[] = "0123456789abcdef";
    for (int i = 15; i >= 0; --i, hash >>= 4)
        name[i] = digits[hash & 0xF];
    name[16] = '\0';
    std::ofstream out(folder / name, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
}

}  // namespace fins::fuzz
