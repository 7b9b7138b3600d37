// FINS/TCP request path (issue 6 item 12): the session reads and answers with its own
// non-blocking system calls; an answer the kernel does not take at once waits in an
// asynchronous write, and reading waits for it. Nothing is lost or reordered, and the one
// I/O thread goes on serving every other client meanwhile.
#include <gtest/gtest.h>

#include <sys/socket.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <boost/asio/io_context.hpp>

#include "fins/tcp.hpp"
#include "server/frame_builder.hpp"
#include "server/sessions/server.hpp"
#include "server/sessions/tcp_peer.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

constexpr std::uint16_t words = 999;  // the most one MEMORY AREA READ returns (W342 5-3-2)
// FINS/TCP header, FINS response header, command, end code, the words.
constexpr std::size_t answer_size = tcp_header_size + 10 + 2 + 2 + 2 * words;

std::uint16_t pattern(std::size_t word) {
    return static_cast<std::uint16_t>(0xA000 + word * 7);
}

// The most a TCP socket's send buffer grows to (net.ipv4.tcp_wmem, third value).
std::size_t send_buffer_max() {
    std::ifstream in("/proc/sys/net/ipv4/tcp_wmem");
    std::size_t low = 0;
    std::size_t initial = 0;
    std::size_t max = 0;
    if (in >> low >> initial >> max && max > 0) return max;
    return 4U << 20U;
}

TEST(TcpSession, FullSendBufferKeepsEveryAnswerInOrderWhileOthersAreServed) {
    Harness h;
    // D0-D998 in two writes (one MEMORY AREA WRITE carries fewer words than a read).
    for (const std::size_t first : {std::size_t{0}, std::size_t{500}}) {
        const std::size_t n = first == 0 ? 500 : words - 500;
        std::string write = fmt::format("0102 82{:04X}00 {:04X}", first, n);
        for (std::size_t i = first; i < first + n; ++i)
            write += fmt::format(" {:04X}", pattern(i));
        ASSERT_EQ(h.send(write).end_code(), 0x0000);
    }

    asio::io_context io{1};
    auto server = start_tcp_only(io, h.plc);
    ASSERT_TRUE(server.has_value());
    const std::uint16_t port = (*server)->tcp_port();
    struct Running {
        asio::io_context& io;
        std::thread thread;
        ~Running() {
            io.stop();
            thread.join();
        }
    } running{io, std::thread([&] { io.run(); })};

    // A client with a small receive window pipelines more answers than its window and the
    // server's largest send buffer hold together, and reads nothing for now.
    TcpPeer slow(port, 4096);
    ASSERT_TRUE(slow.handshake());
    const std::size_t count =
        std::min<std::size_t>(20000, 2 * send_buffer_max() / answer_size + 1000);
    std::atomic<std::size_t> sent{0};
    std::thread sender([&] {
        for (std::size_t i = 0; i < count; ++i) {
            const auto packet = slow.read_packet(static_cast<std::uint8_t>(i), words);
            if (!slow.send_all(packet.data(), packet.size())) return;
            sent = i + 1;
        }
    });
    struct Join {
        std::thread& t;
        ~Join() {
            if (t.joinable()) t.join();
        }
    } join{sender};

    // Wait (bounded) until the sender makes no progress: it sent everything, or the
    // session stopped reading because an answer waits for the full send buffer. Either
    // way more answers than any kernel buffer holds are owed now (count's choice).
    std::size_t seen = 0;
    for (int i = 0; i < 100; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (sent.load() == seen && seen > 0) break;
        seen = sent.load();
    }
    ASSERT_GT(sent.load(), 0U);

    // Meanwhile another client on the same I/O thread is answered, request after request.
    TcpPeer other(port);
    ASSERT_TRUE(other.handshake());
    for (std::uint8_t sid = 1; sid <= 20; ++sid)
        ASSERT_EQ(other.read_word(sid), 0x0000) << "sid " << int{sid};

    // Now the slow client reads: every answer, whole, in the order asked, with the data.
    std::vector<std::uint8_t> answer(answer_size);
    for (std::size_t i = 0; i < count; ++i) {
        ASSERT_TRUE(slow.receive(answer.data(), answer.size()))
            << "answer " << i << " of " << count << " (" << sent.load() << " sent)";
        const TcpParse parsed = parse_tcp_frame(answer);
        ASSERT_EQ(parsed.status, TcpParse::Status::packet) << "answer " << i;
        ASSERT_EQ(parsed.consumed, answer_size) << "answer " << i;
        const Bytes frame = parsed.packet.data;
        ASSERT_EQ(frame[9], static_cast<std::uint8_t>(i)) << "answer " << i;  // SID
        ASSERT_EQ((frame[12] << 8) | frame[13], 0x0000) << "answer " << i;
        for (std::size_t w = 0; w < words; ++w)
            ASSERT_EQ((frame[14 + 2 * w] << 8) | frame[15 + 2 * w], pattern(w))
                << "answer " << i << " word " << w;
    }
    sender.join();
    EXPECT_EQ(sent.load(), count);
    // And nothing more: no answer twice.
    std::uint8_t extra = 0;
    EXPECT_EQ(::recv(slow.fd(), &extra, 1, MSG_DONTWAIT), -1);
}

}  // namespace
}  // namespace fins::test
