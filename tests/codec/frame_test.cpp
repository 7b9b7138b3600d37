// FINS header and whole-frame codecs (frames 1.1-1.6).
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"

namespace fins {
namespace {

using test::hex;

Header sample_header() {
    Header h;
    h.icf = icf_gateway;
    h.gateway_count = default_gateway_count;
    h.destination = {0x00, 0x01, 0x00};
    h.source = {0x00, 0x0A, 0x00};
    h.service_id = 0x12;
    return h;
}

std::vector<std::uint8_t> encode_frame(const Header& h, CommandCode c, Bytes params) {
    std::vector<std::uint8_t> out(max_frame_size);
    auto n = encode_request(h, c, params, out);
    EXPECT_TRUE(n.has_value());
    out.resize(n.value_or(0));
    return out;
}

TEST(Frame, HeaderRoundTrip) {
    Header h = sample_header();
    h.icf = 0x81;
    h.reserved = 0x00;
    h.gateway_count = 0x07;
    std::array<std::uint8_t, header_size> buf{};
    ByteWriter w(buf);
    write_header(w, h);
    EXPECT_EQ(w.size(), header_size);
    EXPECT_FALSE(w.overflowed());
    ByteReader r(buf);
    EXPECT_EQ(read_header(r), h);
    EXPECT_TRUE(r.complete());
    EXPECT_FALSE(h.response_required());
}

TEST(Frame, GoldenMemoryAreaReadD10) {
    // The manual's example: reading 10 words from D10.
    const auto v = test::load_vector("memory_area_read_d10.txt");
    ASSERT_FALSE(v.source.empty());
    ASSERT_EQ(v.lines.size(), 1u);
    const auto golden = hex(v.lines[0]);

    MemoryAreaRead read{{0x82, 10, 0}, 10};
    auto params = test::encode(read);
    std::vector<std::uint8_t> bytes{MemoryAreaRead::code.main, MemoryAreaRead::code.sub};
    bytes.insert(bytes.end(), params.begin(), params.end());
    EXPECT_EQ(bytes, golden);
}

TEST(Frame, GoldenRequestAndResponseFrames) {
    const auto v = test::load_vector("memory_area_read_d10_frame.txt");
    ASSERT_FALSE(v.source.empty());
    ASSERT_EQ(v.lines.size(), 2u);
    const auto request = hex(v.lines[0]);
    const auto response = hex(v.lines[1]);

    MemoryAreaRead read{{0x82, 10, 0}, 10};
    const auto params = test::encode(read);
    EXPECT_EQ(encode_frame(sample_header(), MemoryAreaRead::code, params), request);

    auto req = decode_request(request);
    ASSERT_TRUE(req) << req.error().message();
    EXPECT_EQ(req->header, sample_header());
    EXPECT_EQ(req->command, MemoryAreaRead::code);
    auto decoded = MemoryAreaRead::decode(req->parameters);
    ASSERT_TRUE(decoded);
    EXPECT_EQ(decoded->start, read.start);
    EXPECT_EQ(decoded->count, 10);

    // The responder's prefix reproduces the golden response header.
    std::vector<std::uint8_t> out(max_frame_size);
    ByteWriter w(out);
    write_response_prefix(w, response_header(req->header, {0x00, 0x01, 0x00}), req->command,
                          0x0000);
    for (std::uint16_t i = 1; i <= 10; ++i)
        w.u16(i);
    out.resize(w.size());
    EXPECT_EQ(out, response);

    auto rsp = decode_response(response);
    ASSERT_TRUE(rsp);
    EXPECT_TRUE(rsp->code.ok());
    EXPECT_FALSE(rsp->relay);
    auto data = read.decode_response(rsp->data);
    ASSERT_TRUE(data);
    EXPECT_EQ(data->data.size(), 20u);
    EXPECT_EQ(data->data[19], 0x0A);
}

TEST(Frame, RequestRoundTripAndEveryShorterPrefixFails) {
    const auto params = hex("82 00 0A 00 00 0A");
    const auto frame = encode_frame(sample_header(), {0x01, 0x01}, params);
    ASSERT_EQ(frame.size(), 18u);
    auto req = decode_request(frame);
    ASSERT_TRUE(req);
    EXPECT_EQ(std::vector<std::uint8_t>(req->parameters.begin(), req->parameters.end()), params);
    // Anything without a whole header and command code is too short.
    for (std::size_t n = 0; n < header_size + command_code_size; ++n) {
        auto r = decode_request(test::prefix(frame, n));
        ASSERT_FALSE(r) << n;
        EXPECT_EQ(r.error(), EndCode::command_too_short) << n;
    }
    // With a command code, shorter parameter blocks are the command decoder's business.
    for (std::size_t n = header_size + command_code_size; n <= frame.size(); ++n) {
        auto r = decode_request(test::prefix(frame, n));
        ASSERT_TRUE(r) << n;
        EXPECT_EQ(r->parameters.size(), n - 12);
    }
}

TEST(Frame, RequestLimits) {
    std::vector<std::uint8_t> params(max_parameter_size, 0xAA);
    const auto frame = encode_frame(sample_header(), {0x01, 0x02}, params);
    EXPECT_EQ(frame.size(), max_frame_size);
    EXPECT_TRUE(decode_request(frame));

    auto longer = frame;
    longer.push_back(0);
    EXPECT_EQ(decode_request(longer).error(), EndCode::command_too_long);

    params.push_back(0);
    std::vector<std::uint8_t> out(4096);
    EXPECT_EQ(encode_request(sample_header(), {0x01, 0x02}, params, out).error(),
              ClientError::request_too_long);
    // An output buffer too small is reported the same way.
    std::vector<std::uint8_t> tiny(17);
    EXPECT_EQ(encode_request(sample_header(), {0x01, 0x01}, hex("82 00 0A 00 00 0A"), tiny).error(),
              ClientError::request_too_long);
}

TEST(Frame, RequestWithResponseBitIsHeaderError) {
    auto frame = hex("C0 00 02 00 01 00 00 0A 00 12 01 01");
    EXPECT_EQ(decode_request(frame).error(), EndCode::header_error);
}

TEST(Frame, ResponseRoundTripAndEveryShorterPrefixFails) {
    const auto frame = hex("C0 00 02 00 0A 00 00 01 00 12 01 01 00 40 12 34");
    auto rsp = decode_response(frame);
    ASSERT_TRUE(rsp);
    EXPECT_TRUE(rsp->code.ok());
    EXPECT_TRUE(rsp->code.non_fatal_cpu_error());
    EXPECT_EQ(rsp->header.service_id, 0x12);
    EXPECT_EQ(rsp->data.size(), 2u);
    for (std::size_t n = 0; n < 14; ++n) {
        auto r = decode_response(test::prefix(frame, n));
        ASSERT_FALSE(r) << n;
        EXPECT_EQ(r.error(), ClientError::malformed_response);
    }
}

TEST(Frame, ResponseWithoutResponseBitIsMalformed) {
    const auto frame = hex("80 00 02 00 0A 00 00 01 00 12 01 01 00 00");
    EXPECT_EQ(decode_response(frame).error(), ClientError::malformed_response);
}

TEST(Frame, ResponseRelayErrorWord) {
    // W342 5-1-3: bit 15 adds the network and node where relaying failed.
    const auto frame = hex("C0 00 02 00 0A 00 00 01 00 12 01 01 85 02 03 07");
    auto rsp = decode_response(frame);
    ASSERT_TRUE(rsp);
    EXPECT_TRUE(rsp->code.relay_error());
    EXPECT_EQ(rsp->code.end_code(), EndCode::no_routing_tables);
    ASSERT_TRUE(rsp->relay);
    EXPECT_EQ(*rsp->relay, (RelayErrorSource{0x03, 0x07}));
    EXPECT_TRUE(rsp->data.empty());
    // Missing or half relay word.
    for (std::size_t n : {14u, 15u}) {
        EXPECT_EQ(decode_response(test::prefix(frame, n)).error(), ClientError::malformed_response)
            << n;
    }
}

TEST(Frame, ResponseHeaderSwapsAndEchoes) {
    Header req = sample_header();
    req.destination = {0x05, 0x21, 0x00};
    req.source = {0x03, 0x0A, 0x01};
    req.gateway_count = 0x07;
    req.service_id = 0xFE;
    const auto h = response_header(req, {0x05, 0x21, 0x00});
    EXPECT_EQ(h.icf, 0xC0);
    EXPECT_EQ(h.reserved, 0);
    EXPECT_EQ(h.gateway_count, 0x07);
    EXPECT_EQ(h.destination, req.source);
    EXPECT_EQ(h.source, req.destination);
    EXPECT_EQ(h.service_id, 0xFE);
    EXPECT_TRUE(h.is_response());
}

// Choice where the manual is silent (frames 1.5): a request that addressed the responder
// as local network 00 and/or node 00 is answered with the responder's real network and
// node; a non-zero value is echoed even if it differs; the unit is always echoed.
TEST(Frame, ResponseHeaderReplacesLocalZeroesWithRealAddress) {
    Header req = sample_header();
    req.destination = {0x00, 0x00, 0x00};
    auto h = response_header(req, {0x02, 0x17, 0x00});
    EXPECT_EQ(h.source, (NodeAddress{0x02, 0x17, 0x00}));

    req.destination = {0x00, 0x05, 0x10};
    h = response_header(req, {0x02, 0x17, 0x00});
    EXPECT_EQ(h.source, (NodeAddress{0x02, 0x05, 0x10}));

    req.destination = {0x04, 0x00, 0x00};
    h = response_header(req, {0x02, 0x17, 0x00});
    EXPECT_EQ(h.source, (NodeAddress{0x04, 0x17, 0x00}));

    // The no-response bit is carried over; the dispatcher decides not to send.
    req.icf = 0x81;
    EXPECT_EQ(response_header(req, {}).icf, 0xC1);
}

TEST(Frame, WriteResponsePrefix) {
    std::array<std::uint8_t, 14> buf{};
    ByteWriter w(buf);
    write_response_prefix(w, response_header(sample_header(), {0, 1, 0}), {0x01, 0x02}, 0x2102);
    EXPECT_EQ(w.size(), 14u);
    EXPECT_FALSE(w.overflowed());
    EXPECT_EQ(std::vector<std::uint8_t>(buf.begin(), buf.end()),
              hex("C0 00 02 00 0A 00 00 01 00 12 01 02 21 02"));
}

}  // namespace
}  // namespace fins
