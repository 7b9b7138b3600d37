// 01 01 must not allocate: the data goes straight into the response buffer.
// This file replaces the global operator new of test_server to count calls.
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <new>

#include <boost/asio/generic/datagram_protocol.hpp>
#include <boost/asio/io_context.hpp>

#include "server/frame_builder.hpp"
#include "server/sessions/udp_session.hpp"
#include "transport/asio.hpp"

namespace {
std::atomic<std::size_t> allocations{0};
}

// The replaced operator new takes from malloc, so its delete frees: at -O3 (the arm64
// Release tree) GCC 12 sees free() of a new'd pointer once inlined, and warns falsely.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
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

// The FINS/UDP path (issue 6 item 12): after the first datagrams (Asio's per-thread
// handler memory, the reactor's registration), serving batches allocates nothing.
TEST(UdpSession, ServingDatagramsDoesNotAllocate) {
    Harness h;
    asio::io_context io{1};
    std::array<int, 2> fds{};
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_DGRAM, 0, fds.data()), 0);
    auto session = std::make_shared<server::UdpSession>(
        asio::generic::datagram_protocol::socket{io, asio::generic::datagram_protocol(AF_UNIX, 0),
                                                 fds[0]},
        h.dispatcher);
    session->start();
    const auto frame = request_frame("0101 82000000 0001");
    std::array<std::uint8_t, 64> in{};
    // Sends `count` requests (fewer than the peer's queue holds) and serves them.
    const auto round = [&](std::size_t count) {
        for (std::size_t i = 0; i < count; ++i)
            if (::send(fds[1], frame.data(), frame.size(), 0) != static_cast<ssize_t>(frame.size()))
                return false;
        std::size_t answered = 0;
        for (int spin = 0; spin < 500 && answered < count; ++spin) {
            io.run_one_for(std::chrono::milliseconds(10));
            while (::recv(fds[1], in.data(), in.size(), MSG_DONTWAIT) > 0)
                ++answered;
        }
        return answered == count;
    };
    ASSERT_TRUE(round(8));
    const auto before = allocations.load();
    for (int i = 0; i < 4; ++i)
        ASSERT_TRUE(round(8));
    EXPECT_EQ(allocations.load(), before);
    session->close();
    ::close(fds[1]);
}

}  // namespace
}  // namespace fins::test
