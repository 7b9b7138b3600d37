// FINS over Host Link (W342 3-5, 5-3-1; fins-frames.md section 4, frames-serial-files.md
// section 3): both command forms, both response forms, error answers, the FCS, the
// length limits, the frame finder fed at every split.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <fmt/core.h>

#include "codec/test_support.hpp"
#include "fins/host_link.hpp"

namespace fins {
namespace {

using test::hex;

std::vector<std::uint8_t> ascii(std::string_view s) {
    return {s.begin(), s.end()};
}
std::string text(Bytes b) {
    return {b.begin(), b.end()};
}

// The manual's MEMORY AREA READ of 10 words from D10 (W342 5-3-2), SID 12.
const auto read_d10 = hex("80 00 02 00 00 00 00 00 00 12 01 01 82 00 0A 00 00 0A");

std::string encode_command(std::uint8_t unit, std::uint8_t wait, HostLinkForm form,
                           const std::vector<std::uint8_t>& fins) {
    std::vector<std::uint8_t> out(host_link_max_command_chars);
    auto n = encode_host_link_command(unit, wait, form, fins, out);
    EXPECT_TRUE(n) << n.error().message();
    return n ? text(Bytes{out.data(), *n}) : std::string{};
}

TEST(HostLink, W342_3_5_FcsIsXorFromAtThroughText) {
    // HSL's example response (frames-serial-files.md section 3): FCS 40.
    EXPECT_EQ(host_link_fcs(ascii("@00FA004000000001020000")), 0x40);
    EXPECT_EQ(host_link_fcs(ascii("")), 0x00);
    EXPECT_EQ(host_link_fcs(ascii("@")), 0x40);
}

TEST(HostLink, W342_3_5_DirectCommandLayout) {
    const auto s = encode_command(0, 0, HostLinkForm::direct, read_d10);
    // "@" 00 "FA" wait ICF DA2 SA2 SID, command code at character 14.
    EXPECT_EQ(s.substr(0, 14), "@00FA000000012");
    EXPECT_EQ(s.substr(14, 4), "0101");
    EXPECT_EQ(s.substr(18, 12), "82000A00000A");
    const auto body = s.substr(0, s.size() - 4);
    EXPECT_EQ(s.substr(s.size() - 4, 2), fmt::format("{:02X}", host_link_fcs(ascii(body))));
    EXPECT_EQ(s.substr(s.size() - 2), "*\r");
}

TEST(HostLink, W342_3_5_NetworkCommandCarriesTheWholeHeader) {
    auto fins = read_d10;
    fins[3] = 0x01;  // DNA
    fins[4] = 0x0A;  // DA1
    const auto s = encode_command(31, 0xF, HostLinkForm::network, fins);
    EXPECT_EQ(s.substr(0, 6), "@31FAF");
    EXPECT_EQ(s.substr(6, 20), "800002010A0000000012");
    EXPECT_EQ(s.substr(26, 4), "0101");
}

TEST(HostLink, CommandsRoundTripInBothForms) {
    for (auto form : {HostLinkForm::direct, HostLinkForm::network}) {
        const auto s = encode_command(7, 3, form, read_d10);
        std::vector<std::uint8_t> fins(host_link_max_fins_response);
        auto f = decode_host_link(ascii(s), false, fins);
        ASSERT_TRUE(f);
        EXPECT_EQ(f->unit, 7);
        EXPECT_EQ(f->wait, 3);
        EXPECT_EQ(f->form, form);
        EXPECT_FALSE(f->response);
        fins.resize(f->fins_size);
        auto expected = read_d10;
        if (form == HostLinkForm::direct) expected[0] = 0x00;  // direct form: ICF "00"
        EXPECT_EQ(fins, expected);
        auto request = decode_request(fins);
        ASSERT_TRUE(request);
        EXPECT_EQ(request->command, (CommandCode{0x01, 0x01}));
        EXPECT_EQ(request->header.service_id, 0x12);
        // Every shorter prefix is not a frame.
        for (std::size_t n = 0; n < s.size(); ++n)
            EXPECT_FALSE(decode_host_link(ascii(s.substr(0, n)), false, fins)) << n;
    }
}

TEST(HostLink, W342_3_5_DirectResponseMatchesTheHslExample) {
    // @00FA00 40 00 00 00 0102 0000 FCS "*" CR: command code at 15, MRES at 19.
    const auto s = ascii("@00FA00400000000102000040*\r");
    std::vector<std::uint8_t> fins(host_link_max_fins_response);
    auto f = decode_host_link(s, true, fins);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->form, HostLinkForm::direct);
    EXPECT_EQ(f->end_code, HostLinkEndCode::normal);
    fins.resize(f->fins_size);
    auto response = decode_response(fins);
    ASSERT_TRUE(response);
    EXPECT_EQ(response->command, (CommandCode{0x01, 0x02}));
    EXPECT_TRUE(response->code.ok());
    // And the encoder writes the same characters back.
    std::vector<std::uint8_t> out(host_link_max_response_chars);
    auto n = encode_host_link_response(0, HostLinkForm::direct, fins, out);
    ASSERT_TRUE(n);
    EXPECT_EQ(text(Bytes{out.data(), *n}), "@00FA00400000000102000040*\r");
}

TEST(HostLink, NetworkResponseRoundTrips) {
    const auto fins = hex("C0 00 02 00 00 00 01 0A 00 12 01 01 00 00 12 34");
    std::vector<std::uint8_t> out(host_link_max_response_chars);
    auto n = encode_host_link_response(5, HostLinkForm::network, fins, out);
    ASSERT_TRUE(n);
    const auto s = text(Bytes{out.data(), *n});
    EXPECT_EQ(s.substr(0, 9), "@05FA00C0");
    std::vector<std::uint8_t> back(host_link_max_fins_response);
    auto f = decode_host_link(Bytes{out.data(), *n}, true, back);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->form, HostLinkForm::network);
    back.resize(f->fins_size);
    EXPECT_EQ(back, fins);
}

TEST(HostLink, W342p125_ErrorAnswerCarriesNoFinsPart) {
    std::vector<std::uint8_t> out(host_link_error_size);
    ASSERT_EQ(encode_host_link_error(3, HostLinkEndCode::fcs_error, out), host_link_error_size);
    const auto s = text(out);
    EXPECT_EQ(s.substr(0, 7), "@03FA13");
    std::vector<std::uint8_t> fins(host_link_max_fins_response);
    auto f = decode_host_link(out, true, fins);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->end_code, HostLinkEndCode::fcs_error);
    EXPECT_EQ(f->fins_size, 0u);
    EXPECT_EQ(make_error_code(HostLinkEndCode::fcs_error).message(),
              "FCS error (Host Link end code 13)");
}

TEST(HostLink, OfFormOfTheCpuInitiatedCommand) {
    const auto fins = hex("80 00 07 00 00 00 00 00 00 01 01 02");
    std::vector<std::uint8_t> out(host_link_max_command_chars);
    auto n =
        encode_host_link_command(0, 0, HostLinkForm::network, fins, out, HostLinkHeaderCode::of);
    ASSERT_TRUE(n);
    EXPECT_EQ(text(Bytes{out.data(), 6}), "@00OF0");
    std::vector<std::uint8_t> back(host_link_max_fins_response);
    auto f = decode_host_link(Bytes{out.data(), *n}, false, back);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->header_code, HostLinkHeaderCode::of);
}

TEST(HostLink, DecodeErrorsAndTheAnswerASlaveGives) {
    std::vector<std::uint8_t> fins(host_link_max_fins_response);
    auto good = encode_command(2, 0, HostLinkForm::direct, read_d10);
    auto bad_fcs = good;
    bad_fcs[bad_fcs.size() - 3] = bad_fcs[bad_fcs.size() - 3] == '0' ? '1' : '0';
    auto e = decode_host_link(ascii(bad_fcs), false, fins);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().error, HostLinkError::bad_fcs);
    EXPECT_EQ(e.error().unit, 2);
    EXPECT_EQ(host_link_answer_for(e.error()), HostLinkEndCode::fcs_error);

    // A C-mode command (header RD) with a good FCS: command not supported (16).
    std::string rd = "@02RD00000001";
    rd += fmt::format("{:02X}*\r", host_link_fcs(ascii(rd)));
    e = decode_host_link(ascii(rd), false, fins);
    ASSERT_FALSE(e);
    EXPECT_TRUE(e.error().not_fins);
    EXPECT_EQ(host_link_answer_for(e.error()), HostLinkEndCode::command_not_supported);

    // Odd hex text with a good FCS: format error (14).
    std::string odd = "@02FA0000000000101820";
    odd += fmt::format("{:02X}*\r", host_link_fcs(ascii(odd)));
    e = decode_host_link(ascii(odd), false, fins);
    ASSERT_FALSE(e);
    EXPECT_EQ(host_link_answer_for(e.error()), HostLinkEndCode::format_error);

    // Unit number not decimal or over 31: nobody can tell whom it was for.
    std::string unit = "@32FA0000000000101";
    unit += fmt::format("{:02X}*\r", host_link_fcs(ascii(unit)));
    e = decode_host_link(ascii(unit), false, fins);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().unit, -1);

    // A response where a command is expected is a format error.
    EXPECT_FALSE(decode_host_link(ascii("@00FA00400000000102000040*\r"), false, fins));
}

TEST(HostLink, W342p69_LengthLimits) {
    // 540 parameter bytes fit a network command of exactly 1,114 characters.
    std::vector<std::uint8_t> fins(host_link_max_fins_command, 0);
    fins[0] = 0x80;
    fins[2] = 0x02;
    fins[10] = 0x01;
    fins[11] = 0x02;
    std::vector<std::uint8_t> out(2048);
    auto n = encode_host_link_command(0, 0, HostLinkForm::network, fins, out);
    ASSERT_TRUE(n);
    EXPECT_EQ(*n, host_link_max_command_chars);
    std::vector<std::uint8_t> back(host_link_max_fins_response);
    EXPECT_TRUE(decode_host_link(Bytes{out.data(), *n}, false, back));
    // One byte more does not encode.
    fins.push_back(0);
    auto too = encode_host_link_command(0, 0, HostLinkForm::network, fins, out);
    ASSERT_FALSE(too);
    EXPECT_EQ(too.error(), make_error_code(HostLinkError::too_long));
    // A terminated command of 1,116 characters: frame length error (18).
    std::string s = "@00FA0800002000000000000000102" + std::string(1116 - 30 - 4, '0');
    s += fmt::format("{:02X}*\r", host_link_fcs(ascii(s)));
    ASSERT_EQ(s.size(), 1116u);
    auto e = decode_host_link(ascii(s), false, back);
    ASSERT_FALSE(e);
    EXPECT_EQ(host_link_answer_for(e.error()), HostLinkEndCode::frame_length_error);
    // Responses: 538 data bytes fit in 1,115 characters.
    std::vector<std::uint8_t> response(host_link_max_fins_response, 0);
    response[0] = 0xC0;
    n = encode_host_link_response(0, HostLinkForm::network, response, out);
    ASSERT_TRUE(n);
    EXPECT_EQ(*n, host_link_max_response_chars);
    EXPECT_TRUE(decode_host_link(Bytes{out.data(), *n}, true, back));
}

TEST(HostLink, FinderSplitsAStreamAtEverySplitPoint) {
    const std::string a = encode_command(0, 0, HostLinkForm::direct, read_d10);
    const std::string b = encode_command(1, 0, HostLinkForm::network, read_d10);
    const std::string stream = "xx\r" + a + "@0" + b + "junk";
    // Feed the stream in two parts at every split point; collect the frames.
    for (std::size_t split = 0; split <= stream.size(); ++split) {
        std::string buffer;
        std::vector<std::string> frames;
        auto drain = [&] {
            for (int guard = 0; guard < 100; ++guard) {
                const auto bytes = ascii(buffer);
                auto s = scan_host_link(bytes);
                if (s.status == HostLinkScan::Status::need_more) return;
                if (s.status == HostLinkScan::Status::frame) frames.push_back(text(s.frame));
                ASSERT_GT(s.consumed, 0u);
                buffer.erase(0, s.consumed);
            }
        };
        buffer += stream.substr(0, split);
        drain();
        buffer += stream.substr(split);
        drain();
        ASSERT_EQ(frames.size(), 2u) << split;
        EXPECT_EQ(frames[0], a);
        EXPECT_EQ(frames[1], b);
    }
}

TEST(HostLink, FinderBoundsAnUnterminatedFrame) {
    const std::string s = "@00FA" + std::string(2000, '0');
    auto r = scan_host_link(ascii(s), 1115);
    EXPECT_EQ(r.status, HostLinkScan::Status::too_long);
    EXPECT_EQ(r.consumed, 1115u);
    // Then the rest is garbage up to the next "@".
    r = scan_host_link(ascii(s.substr(1115) + "@"));
    EXPECT_EQ(r.status, HostLinkScan::Status::garbage);
    EXPECT_EQ(r.consumed, s.size() - 1115);
    EXPECT_EQ(scan_host_link(ascii("@00FA0")).status, HostLinkScan::Status::need_more);
}

}  // namespace
}  // namespace fins
