// The FINS/TCP envelope (W421 7-4, frames 3): every packet kind, fed split at every byte
// and glued back to back; bad magic and bad lengths.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/tcp.hpp"

namespace fins {
namespace {

using test::hex;
using test::prefix;

std::vector<std::vector<std::uint8_t>> golden_packets() {
    const auto v = test::load_vector("tcp_handshake.txt");
    EXPECT_FALSE(v.source.empty());
    std::vector<std::vector<std::uint8_t>> out;
    for (const auto& line : v.lines)
        out.push_back(hex(line));
    EXPECT_EQ(out.size(), 5u);
    return out;
}

template <class F>
std::vector<std::uint8_t> write(F&& f) {
    std::vector<std::uint8_t> buf(tcp_max_packet);
    ByteWriter w(buf);
    f(w);
    EXPECT_FALSE(w.overflowed());
    buf.resize(w.size());
    return buf;
}

TEST(Tcp, WritersMatchGoldenPackets) {
    const auto g = golden_packets();
    EXPECT_EQ(write([](ByteWriter& w) { write_node_address_request(w, 0); }), g[0]);
    EXPECT_EQ(write([](ByteWriter& w) { write_node_address_response(w, 0x0A, 0x01); }), g[1]);
    const auto frame = hex("80 00 02 00 01 00 00 0A 00 12 01 01 82 00 0A 00 00 0A");
    EXPECT_EQ(write([&](ByteWriter& w) {
                  write_tcp_header(w, TcpCommand::frame, frame.size());
                  w.bytes(frame);
              }),
              g[2]);
    EXPECT_EQ(write([](ByteWriter& w) {
                  write_tcp_error(w, TcpCommand::frame_error, TcpError::not_fins_header);
              }),
              g[3]);
    EXPECT_EQ(
        write([](ByteWriter& w) { write_tcp_header(w, TcpCommand::connection_confirmation, 0); }),
        g[4]);
    EXPECT_EQ(g[0].size(), 20u);
    EXPECT_EQ(g[1].size(), 24u);
    EXPECT_EQ(g[3].size(), 16u);
}

TEST(Tcp, ParseEveryKindSplitAtEveryByte) {
    const std::uint32_t commands[] = {0, 1, 2, 3, 6};
    const auto g = golden_packets();
    for (std::size_t k = 0; k < g.size(); ++k) {
        const auto& packet = g[k];
        for (std::size_t n = 0; n < packet.size(); ++n) {
            const auto p = parse_tcp_frame(prefix(packet, n));
            ASSERT_EQ(p.status, TcpParse::Status::need_more) << k << " at " << n;
        }
        const auto p = parse_tcp_frame(packet);
        ASSERT_EQ(p.status, TcpParse::Status::packet) << k;
        EXPECT_EQ(p.consumed, packet.size());
        EXPECT_EQ(p.packet.command, commands[k]);
        EXPECT_EQ(p.packet.data.size(), packet.size() - tcp_header_size);
    }
    const auto error = parse_tcp_frame(g[3]);
    EXPECT_EQ(error.packet.error, 1u);
}

TEST(Tcp, HandshakeData) {
    const auto g = golden_packets();
    auto req = parse_tcp_frame(g[0]);
    auto node = decode_node_address_request(req.packet.data);
    ASSERT_TRUE(node);
    EXPECT_EQ(*node, 0);
    auto rsp = parse_tcp_frame(g[1]);
    auto nodes = decode_node_address_response(rsp.packet.data);
    ASSERT_TRUE(nodes);
    EXPECT_EQ(nodes->client_node, 0x0A);
    EXPECT_EQ(nodes->server_node, 0x01);
    // Only the last byte of each 4-byte field counts (frames 3.2).
    EXPECT_EQ(decode_node_address_request(hex("00 00 00 FE")).value(), 0xFE);
    for (std::size_t n = 0; n < 4; ++n) {
        EXPECT_EQ(decode_node_address_request(prefix(hex("00000005"), n)).error(),
                  TcpError::data_length_too_long);
    }
    EXPECT_EQ(decode_node_address_request(hex("00 00 00 05 00")).error(),
              TcpError::data_length_too_long);
    // W421 7-4: 00000000-000000FE. Above FE the whole value is out of range, not its
    // low byte (00000105 is not node 5).
    EXPECT_EQ(decode_node_address_request(hex("00 00 00 FF")).error(),
              TcpError::client_node_out_of_range);
    EXPECT_EQ(decode_node_address_request(hex("00 00 01 05")).error(),
              TcpError::client_node_out_of_range);
    EXPECT_EQ(decode_node_address_request(hex("80 00 00 01")).error(),
              TcpError::client_node_out_of_range);
    const auto eight = hex("00 00 00 0A 00 00 00 01");
    for (std::size_t n = 0; n < eight.size(); ++n) {
        EXPECT_EQ(decode_node_address_response(prefix(eight, n)).error(),
                  ClientError::malformed_response);
    }
    // The error field rides in the header of command 1 (frames 3.4 step 2).
    const auto refused = write([](ByteWriter& w) {
        write_node_address_response(w, 0x0A, 0x01, static_cast<std::uint32_t>(0x21));
    });
    EXPECT_EQ(parse_tcp_frame(refused).packet.error, 0x21u);
}

TEST(Tcp, PacketsGluedBackToBack) {
    const auto g = golden_packets();
    std::vector<std::uint8_t> stream;
    for (const auto& p : g)
        stream.insert(stream.end(), p.begin(), p.end());
    std::size_t offset = 0;
    for (const auto& expected : g) {
        const auto p = parse_tcp_frame(Bytes(stream).subspan(offset));
        ASSERT_EQ(p.status, TcpParse::Status::packet);
        EXPECT_EQ(p.consumed, expected.size());
        offset += p.consumed;
    }
    EXPECT_EQ(offset, stream.size());
    EXPECT_EQ(parse_tcp_frame(Bytes(stream).subspan(offset)).status, TcpParse::Status::need_more);
}

TEST(Tcp, StreamFedByteByByte) {
    // A transport that appends one byte at a time and consumes whole packets.
    const auto g = golden_packets();
    std::vector<std::uint8_t> stream;
    for (const auto& p : g)
        stream.insert(stream.end(), p.begin(), p.end());
    std::vector<std::uint8_t> buffer;
    std::vector<std::uint32_t> seen;
    for (auto byte : stream) {
        buffer.push_back(byte);
        const auto p = parse_tcp_frame(buffer);
        ASSERT_NE(p.status, TcpParse::Status::error);
        if (p.status == TcpParse::Status::packet) {
            seen.push_back(p.packet.command);
            buffer.erase(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(p.consumed));
        }
    }
    EXPECT_EQ(seen, (std::vector<std::uint32_t>{0, 1, 2, 3, 6}));
    EXPECT_TRUE(buffer.empty());
}

TEST(Tcp, BadMagicDetectedEarly) {
    const auto bad = hex("46 49 4E 54 00 00 00 08 00 00 00 02 00 00 00 00");
    for (std::size_t n = 0; n < 3; ++n)
        EXPECT_EQ(parse_tcp_frame(prefix(bad, n)).status, TcpParse::Status::need_more) << n;
    for (std::size_t n = 4; n <= bad.size(); ++n) {
        const auto p = parse_tcp_frame(prefix(bad, n));
        ASSERT_EQ(p.status, TcpParse::Status::error) << n;
        EXPECT_EQ(p.error, TcpError::not_fins_header);
    }
    // A first byte that is not 'F' is refused at once.
    const auto http = parse_tcp_frame(hex("47"));
    EXPECT_EQ(http.status, TcpParse::Status::error);
    EXPECT_EQ(http.consumed, 1u);
}

TEST(Tcp, BadLength) {
    // Below 8 (no room for command and error) and above 8 + 2,012.
    for (std::uint32_t length : {0u, 7u, tcp_max_length + 1, 0xFFFFFFFFu}) {
        auto packet = write([&](ByteWriter& w) {
            w.u32(tcp_magic);
            w.u32(length);
        });
        const auto p = parse_tcp_frame(packet);
        ASSERT_EQ(p.status, TcpParse::Status::error) << length;
        EXPECT_EQ(p.error, TcpError::data_length_too_long);
        EXPECT_EQ(p.consumed, 8u);
        // Only the magic and length are needed to tell.
        EXPECT_EQ(parse_tcp_frame(prefix(packet, 7)).status, TcpParse::Status::need_more);
    }
    // Exactly the limit is a packet once complete.
    std::vector<std::uint8_t> max_frame(max_frame_size, 0x55);
    auto packet = write([&](ByteWriter& w) {
        write_tcp_header(w, TcpCommand::frame, max_frame.size());
        w.bytes(max_frame);
    });
    EXPECT_EQ(packet.size(), tcp_max_packet);
    const auto p = parse_tcp_frame(packet);
    ASSERT_EQ(p.status, TcpParse::Status::packet);
    EXPECT_EQ(p.packet.data.size(), max_frame_size);
    EXPECT_EQ(parse_tcp_frame(prefix(packet, packet.size() - 1)).status,
              TcpParse::Status::need_more);
}

TEST(Tcp, UnknownCommandIsReturnedAsPacket) {
    const auto p = parse_tcp_frame(hex("46 49 4E 53 00 00 00 08 00 00 00 07 00 00 00 00"));
    ASSERT_EQ(p.status, TcpParse::Status::packet);
    EXPECT_EQ(p.packet.command, 7u);
}

}  // namespace
}  // namespace fins
