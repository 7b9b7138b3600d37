// 01 01 must not allocate: the data goes straight into the response buffer.
// This file replaces the global operator new of test_server to count calls.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "server/frame_builder.hpp"

namespace {
std::atomic<std::size_t> allocations{0};
}

void* operator new(std::size_t size) {
    allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}

namespace fins::test {
namespace {

TEST(MemoryAreaRead, MemoryAreaReadPathDoesNotAllocate) {
    Harness h;
    std::array<std::uint8_t, max_frame_size> out{};
    for (const char* command : {"0101 82000000 03E7", "0101 30000A0F 0100", "0101 FF000000 0001",
                                "0101 82800000 0001", "0101 82000000 03E8"}) {
        const auto frame = request_frame(command);
        const auto before = allocations.load();
        const auto n = h.dispatcher.handle(frame, out, h.context);
        EXPECT_EQ(allocations.load(), before) << command;
        EXPECT_GE(n, 14U);
    }
    // The counter works: 01 04 decodes into a vector.
    const auto multiple = request_frame("0104 82000000");
    const auto before = allocations.load();
    h.dispatcher.handle(multiple, out, h.context);
    EXPECT_GT(allocations.load(), before);
}

}  // namespace
}  // namespace fins::test
