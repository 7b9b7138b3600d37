// FINS/TCP on the wire against the real server (frames section 3): the handshake and
// its error codes, requests split at every byte or glued together, envelope errors,
// and peers that vanish mid-frame.
#include <gtest/gtest.h>

#include "integration/support/raw_socket.hpp"
#include "integration/support/server_fixture.hpp"

namespace fins::test {
namespace {

const auto read_d0 = request_frame({0x01, 0x01}, {0x82, 0, 0, 0, 0, 1});

class TcpWire : public ::testing::Test {
  protected:
    ServerThread server{[] {
        server::ServerOptions o;
        o.max_tcp_connections = 3;
        return o;
    }()};
    asio::io_context io;
    RawTcp connect() { return RawTcp(io, "127.0.0.1", server.port()); }
};

TEST_F(TcpWire, HandshakeAllocatesNode239First) {
    auto c = connect();
    auto r = c.handshake(0);
    ASSERT_EQ(r.size(), 24u);
    EXPECT_EQ(be32(r, 0), tcp_magic);
    EXPECT_EQ(be32(r, 4), 16u);
    EXPECT_EQ(be32(r, 8), 1u);   // NODE ADDRESS DATA SEND, server -> client
    EXPECT_EQ(be32(r, 12), 0u);  // no error
    EXPECT_EQ(be32(r, 16), 239u);
    EXPECT_EQ(be32(r, 20), 1u);  // server node on loopback
    auto second = connect();
    EXPECT_EQ(be32(second.handshake(0), 16), 240u);
}

TEST_F(TcpWire, HandshakeErrorsAreSentInCommandOneThenClosed) {
    {
        auto c = connect();
        auto r = c.handshake(1);  // the server's own node
        ASSERT_EQ(r.size(), 24u);
        EXPECT_EQ(be32(r, 12), 0x24u);
        EXPECT_TRUE(c.closed_by_peer());
    }
    {
        auto c = connect();
        EXPECT_EQ(be32(c.handshake(255), 12), 0x23u);
    }
    auto first = connect();
    ASSERT_EQ(be32(first.handshake(20), 12), 0u);
    auto dup = connect();
    EXPECT_EQ(be32(dup.handshake(20), 12), 0x21u);  // node already connected
    auto b = connect();
    ASSERT_EQ(be32(b.handshake(0), 12), 0u);
    auto c3 = connect();
    ASSERT_EQ(be32(c3.handshake(0), 12), 0u);
    auto full = connect();
    EXPECT_EQ(be32(full.handshake(0), 12), 0x20u);  // max_tcp_connections = 3
}

// Every split request reads its own word (D<split>, holding 0x1000 + split) with its own
// SID, so an answer can be told from every other one; a sentinel request at the end must
// be answered next on the wire, so a request answered twice (or a stray byte) fails.
TEST_F(TcpWire, RequestSplitAtEveryBytePositionIsAnsweredOnce) {
    auto c = connect();
    const auto handshake = c.handshake();
    ASSERT_EQ(be32(handshake, 12), 0u);
    const auto node = static_cast<std::uint8_t>(be32(handshake, 16));  // our SA1
    constexpr std::uint16_t words = 64;
    constexpr std::uint16_t base = 0x1000;
    std::vector<std::uint8_t> write{0x82, 0, 0, 0, 0, words};
    for (std::uint16_t i = 0; i < words; ++i) {
        write.push_back(static_cast<std::uint8_t>((base + i) >> 8));
        write.push_back(static_cast<std::uint8_t>(base + i));
    }
    c.send(tcp_packet(TcpCommand::frame, request_frame({0x01, 0x02}, write, 0xF0, node)));
    ASSERT_EQ(end_code_of(c.receive_packet(), tcp_header_size), 0x0000);

    const auto read_word = [&](std::uint16_t word, std::uint8_t sid) {
        return tcp_packet(
            TcpCommand::frame,
            request_frame({0x01, 0x01}, {0x82, 0, static_cast<std::uint8_t>(word), 0, 0, 1}, sid,
                          node));
    };
    // The answer to read_word(word, sid): that SID and the word's value, nothing else.
    const auto expect_answer = [&](std::uint16_t word, std::uint8_t sid, std::size_t split) {
        const auto r = c.receive_packet();
        ASSERT_EQ(r.size(), tcp_header_size + 16) << "split at " << split;
        EXPECT_EQ(r[tcp_header_size + 9], sid) << "split at " << split;
        EXPECT_EQ(end_code_of(r, tcp_header_size), 0x0000) << "split at " << split;
        EXPECT_EQ((r[tcp_header_size + 14] << 8) | r[tcp_header_size + 15], base + word)
            << "split at " << split;
    };
    const std::size_t size = read_word(0, 0).size();
    ASSERT_LT(size, words);
    for (std::size_t split = 1; split < size; ++split) {
        const auto word = static_cast<std::uint16_t>(split);
        const auto packet = read_word(word, static_cast<std::uint8_t>(split));
        c.send({packet.begin(), packet.begin() + static_cast<std::ptrdiff_t>(split)});
        c.send({packet.begin() + static_cast<std::ptrdiff_t>(split), packet.end()});
        expect_answer(word, static_cast<std::uint8_t>(split), split);
    }
    // And one byte per write.
    for (auto b : read_word(static_cast<std::uint16_t>(size), 0x77))
        c.send({b});
    expect_answer(static_cast<std::uint16_t>(size), 0x77, 0);
    // The sentinel: a whole request whose answer must be the very next packet.
    c.send(read_word(words - 1, 0xAA));
    expect_answer(words - 1, 0xAA, 0);
}

TEST_F(TcpWire, GluedRequestsGetOneWholeResponseEach) {
    auto c = connect();
    ASSERT_EQ(be32(c.handshake(), 12), 0u);
    auto a = tcp_packet(TcpCommand::frame, request_frame({0x01, 0x01}, {0x82, 0, 0, 0, 0, 1}, 1));
    auto b = tcp_packet(TcpCommand::frame, request_frame({0x01, 0x01}, {0x82, 0, 0, 0, 0, 2}, 2));
    auto both = a;
    both.insert(both.end(), b.begin(), b.end());
    c.send(both);
    auto r1 = c.receive_packet();
    auto r2 = c.receive_packet();
    ASSERT_EQ(r1.size(), tcp_header_size + 16);
    ASSERT_EQ(r2.size(), tcp_header_size + 18);
    EXPECT_EQ(r1[tcp_header_size + 9], 1);  // SIDs in order
    EXPECT_EQ(r2[tcp_header_size + 9], 2);
}

TEST_F(TcpWire, BadMagicGetsErrorNotificationAndClose) {
    auto c = connect();
    ASSERT_EQ(be32(c.handshake(), 12), 0u);
    auto packet = tcp_packet(TcpCommand::frame, read_d0);
    packet[0] = 'X';
    c.send(packet);
    auto r = c.receive_packet();
    ASSERT_EQ(r.size(), 16u);
    EXPECT_EQ(be32(r, 8), 3u);
    EXPECT_EQ(be32(r, 12), 0x01u);
    EXPECT_TRUE(c.closed_by_peer());
}

TEST_F(TcpWire, OversizedLengthAndSecondHandshakeAreRefused) {
    {
        auto c = connect();
        ASSERT_EQ(be32(c.handshake(), 12), 0u);
        std::vector<std::uint8_t> big(tcp_header_size);
        ByteWriter w{big};
        write_tcp_header(w, TcpCommand::frame, max_frame_size + 1);
        c.send(big);
        auto r = c.receive_packet();
        ASSERT_EQ(r.size(), 16u);
        EXPECT_EQ(be32(r, 12), 0x02u);
    }
    auto c = connect();
    ASSERT_EQ(be32(c.handshake(), 12), 0u);
    auto again = c.handshake();
    ASSERT_EQ(again.size(), 16u);
    EXPECT_EQ(be32(again, 8), 3u);
    EXPECT_EQ(be32(again, 12), 0x03u);
}

TEST_F(TcpWire, FrameBeforeHandshakeIsRefused) {
    auto c = connect();
    c.send(tcp_packet(TcpCommand::frame, read_d0));
    auto r = c.receive_packet();
    ASSERT_EQ(r.size(), 16u);
    EXPECT_EQ(be32(r, 8), 3u);
    EXPECT_TRUE(c.closed_by_peer());
}

TEST_F(TcpWire, PeerDroppingMidFrameFreesItsNode) {
    {
        auto c = connect();
        ASSERT_EQ(be32(c.handshake(), 16), 239u);
        auto packet = tcp_packet(TcpCommand::frame, read_d0);
        c.send({packet.begin(), packet.begin() + 10});
        c.close();
    }
    // The dropped connection's node is free again once the server saw the close; the
    // allocation is deterministic, so wait (bounded) until 239 is handed out again.
    bool reused = false;
    for (int attempt = 0; attempt < 200 && !reused; ++attempt) {
        auto c = connect();
        reused = be32(c.handshake(), 16) == 239u;
    }
    EXPECT_TRUE(reused);
    // And the server still answers.
    auto client = server.client(true);
    ASSERT_NE(client, nullptr);
    EXPECT_TRUE(client->read_words(Address{Area::dm, 0, 0, {}}, 1).has_value());
}

TEST(UdpWire, OversizedAndUndersizedDatagrams) {
    ServerThread server;
    asio::io_context io;
    asio::ip::udp::socket s(io, asio::ip::udp::endpoint(asio::ip::udp::v4(), 0));
    set_receive_timeout(s.native_handle(), 5);
    const asio::ip::udp::endpoint to(asio::ip::make_address("127.0.0.1"), server.port());
    // 2,013 bytes: one more than a FINS frame may have (W596: max 2,012).
    auto big = request_frame({0x01, 0x02}, {0x82, 0, 0, 0, 0x03, 0xE5});
    big.resize(max_frame_size + 1, 0);
    s.send_to(asio::buffer(big), to);
    // Plain recv(): Asio's blocking receive would poll past SO_RCVTIMEO forever.
    std::vector<std::uint8_t> in(4096);
    auto n = ::recv(s.native_handle(), in.data(), in.size(), 0);
    ASSERT_GT(n, 0) << "no answer within the receive timeout";
    in.resize(static_cast<std::size_t>(n));
    EXPECT_EQ(end_code_of(in), 0x1001);
    // Too short to carry a command code: nothing to answer, and the server lives on.
    s.send_to(asio::buffer(std::vector<std::uint8_t>{0x80, 0, 2}), to);
    s.send_to(asio::buffer(request_frame({0x01, 0x01}, {0x82, 0, 0, 0, 0, 1}, 0x42)), to);
    in.assign(4096, 0);
    n = ::recv(s.native_handle(), in.data(), in.size(), 0);
    ASSERT_GT(n, 0) << "no answer within the receive timeout";
    in.resize(static_cast<std::size_t>(n));
    EXPECT_EQ(in[9], 0x42);
    EXPECT_EQ(end_code_of(in), 0x0000);
}

}  // namespace
}  // namespace fins::test
