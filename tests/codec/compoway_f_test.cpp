// CompoWay/F framing (frames-serial-files.md section 1): the BCC worked example, frame
// parsing from a byte stream (noise, restart on STX, split input), command and
// response bodies.
#include <gtest/gtest.h>

#include <string_view>

#include "codec/test_support.hpp"
#include "fins/compoway_f.hpp"

namespace fins::compoway_f {
namespace {

using test::hex;

std::vector<std::uint8_t> ascii(std::string_view s) {
    return {s.begin(), s.end()};
}

std::vector<std::uint8_t> frame(Bytes body) {
    std::vector<std::uint8_t> out(body.size() + 3);
    ByteWriter w(out);
    write_frame(w, body);
    EXPECT_FALSE(w.overflowed());
    return out;
}

TEST(CompowayF, BccWorkedExampleFromTheK3hbManual) {
    // K3HB/E5AR: 30 30 30 30 30 30 35 30 30 03 -> BCC 36.
    EXPECT_EQ(bcc(hex("30 30 30 30 30 30 35 30 30 03")), 0x36);
    const auto f = frame(hex("30 30 30 30 30 30 35 30 30"));
    EXPECT_EQ(f, hex("02 30 30 30 30 30 30 35 30 30 03 36"));
}

TEST(CompowayF, ParsesOneFrameAndSaysNeedMoreForEveryPrefix) {
    const auto body = ascii("0100000101000000000064");
    const auto f = frame(body);
    for (std::size_t n = 0; n < f.size(); ++n)
        EXPECT_EQ(parse_frame(Bytes{f.data(), n}).status, FrameParse::Status::need_more) << n;
    const auto parsed = parse_frame(f);
    ASSERT_EQ(parsed.status, FrameParse::Status::complete);
    EXPECT_EQ(parsed.consumed, f.size());
    EXPECT_TRUE(std::equal(parsed.body.begin(), parsed.body.end(), body.begin(), body.end()));
}

TEST(CompowayF, SkipsNoiseAndRestartsOnSecondStx) {
    auto stream = hex("FF 00 02 31 32");  // noise, then a frame cut short by a new STX
    const auto f = frame(ascii("010000"));
    stream.insert(stream.end(), f.begin(), f.end());
    const auto parsed = parse_frame(stream);
    ASSERT_EQ(parsed.status, FrameParse::Status::complete);
    EXPECT_EQ(parsed.consumed, stream.size());
    EXPECT_EQ(parsed.body.size(), 6U);
}

TEST(CompowayF, BadBccIsReported) {
    auto f = frame(ascii("010000"));
    f.back() ^= 0x01;
    EXPECT_EQ(parse_frame(f).status, FrameParse::Status::bad_checksum);
}

TEST(CompowayF, OverlongFrameIsNotBufferedForever) {
    std::vector<std::uint8_t> stream(max_frame_size + 8, '0');
    stream[0] = stx;
    EXPECT_EQ(parse_frame(stream).status, FrameParse::Status::too_long);
}

TEST(CompowayF, CommandAndResponseBodiesRoundTrip) {
    const auto body = ascii(
        "01000"
        "3005"
        "0100");
    const auto c = decode_command(body);
    ASSERT_TRUE(c);
    std::vector<std::uint8_t> out(64);
    ByteWriter w(out);
    encode_command(w, *c);
    out.resize(w.size());
    EXPECT_EQ(out, body);
    EXPECT_FALSE(decode_command(ascii("01000301")));

    const auto rsp = ascii(
        "0100"
        "00"
        "0101"
        "0000"
        "00000064");
    const auto r = decode_response(rsp);
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->has_text);
    EXPECT_EQ(r->end_code, end_code::normal);
    std::vector<std::uint8_t> back(64);
    ByteWriter w2(back);
    encode_response(w2, *r);
    back.resize(w2.size());
    EXPECT_EQ(back, rsp);

    const auto error =
        decode_response(ascii("0100"
                              "13"));
    ASSERT_TRUE(error);
    EXPECT_FALSE(error->has_text);
    EXPECT_EQ(error->end_code, end_code::bcc);
    for (std::size_t n : {0U, 5U, 7U, 13U})
        EXPECT_FALSE(decode_response(Bytes{rsp.data(), n})) << n;
}

}  // namespace
}  // namespace fins::compoway_f
