// The client against the real server over loopback, once over FINS/UDP and once over
// FINS/TCP: every area and element type, the error end codes, split reads and writes,
// and many requests in flight.
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration/support/server_fixture.hpp"

namespace fins::test {
namespace {

class ClientServer : public ::testing::TestWithParam<bool> {
  protected:
    ServerThread server;
    std::unique_ptr<Client> client = server.client(GetParam());

    Address at(const std::string& text) {
        auto a = parse_address(text);
        EXPECT_TRUE(a.has_value()) << text;
        return a.value_or(Address{});
    }
    RawResponse raw(CommandCode code, const std::vector<std::uint8_t>& params) {
        auto r = client->send_raw(code, params);
        EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message());
        return r.value_or(RawResponse{});
    }
};

INSTANTIATE_TEST_SUITE_P(Transports, ClientServer, ::testing::Values(false, true),
                         [](const auto& p) { return p.param ? "tcp" : "udp"; });

TEST_P(ClientServer, WordsRoundTripInEveryWordArea) {
    ASSERT_NE(client, nullptr);
    const char* areas[] = {"CIO0", "CIO6140",   "W0",      "W509",  "H0",    "H509", "A448",
                           "A957", "T0",        "T4093",   "C0",    "C4093", "D0",   "D32765",
                           "E0_0", "E18_32765", "E15_100", "E16_7", "E100",  "DR0",  "DR13"};
    std::uint16_t seed = 1;
    for (const char* text : areas) {
        const std::vector<std::uint16_t> words{seed, static_cast<std::uint16_t>(seed * 3),
                                               static_cast<std::uint16_t>(0xFFFF - seed)};
        seed = static_cast<std::uint16_t>(seed + 7);
        auto w = client->write_words(at(text), words);
        ASSERT_TRUE(w.has_value()) << text << ": " << w.error().message();
        auto r = client->read_words(at(text), words.size());
        ASSERT_TRUE(r.has_value()) << text << ": " << r.error().message();
        EXPECT_EQ(*r, words) << text;
    }
}

TEST_P(ClientServer, BitsRoundTripAndLandInTheirWord) {
    ASSERT_NE(client, nullptr);
    for (const char* text : {"CIO10.13", "W5.0", "H10.15", "A448.3", "D100.15", "E3_100.7",
                             "E0_0.5", "E100.2", "E18_32766.14"}) {
        const std::vector<bool> bits{true, false, true};
        auto w = client->write_bits(at(text), bits);
        ASSERT_TRUE(w.has_value()) << text << ": " << w.error().message();
        auto r = client->read_bits(at(text), 3);
        ASSERT_TRUE(r.has_value()) << text << ": " << r.error().message();
        EXPECT_EQ(*r, bits) << text;
    }
    // CIO10.13 and .15 set: word CIO10 = 0xA000, and the run continued into CIO11.
    auto word = client->read_words(at("CIO10"), 1);
    ASSERT_TRUE(word.has_value());
    EXPECT_EQ((*word)[0], 0xA000);
    auto carry = client->read_bits(at("H10.15"), 2);
    ASSERT_TRUE(carry.has_value());
    EXPECT_EQ(*carry, (std::vector<bool>{true, false}));
    auto h11 = client->read_words(at("H11"), 1);
    ASSERT_TRUE(h11.has_value());
    EXPECT_EQ((*h11)[0], 0x0002);  // H11.01 came from the third bit of the run at H10.15
}

TEST_P(ClientServer, TypedValuesUseOmronWordOrder) {
    ASSERT_NE(client, nullptr);
    ASSERT_TRUE(client->write_int32(at("D200"), -123456).has_value());
    ASSERT_TRUE(client->write_float(at("D202"), 3.5f).has_value());
    ASSERT_TRUE(client->write_double(at("D204"), -2.25).has_value());
    ASSERT_TRUE(client->write_bcd16(at("D208"), 1234).has_value());
    ASSERT_TRUE(client->write_string(at("D210"), "HELLO").has_value());
    EXPECT_EQ(client->read_int32(at("D200")).value_or(0), -123456);
    EXPECT_EQ(client->read_float(at("D202")).value_or(0), 3.5f);
    EXPECT_EQ(client->read_double(at("D204")).value_or(0), -2.25);
    EXPECT_EQ(client->read_bcd16(at("D208")).value_or(0), 1234);
    EXPECT_EQ(client->read_words(at("D208"), 1).value_or(std::vector<std::uint16_t>{})[0], 0x1234);
    EXPECT_EQ(client->read_string(at("D210"), 3).value_or(""), "HELLO");
    // -123456 = 0xFFFE1DC0: least significant word first.
    EXPECT_EQ(client->read_words(at("D200"), 2).value_or(std::vector<std::uint16_t>{}),
              (std::vector<std::uint16_t>{0x1DC0, 0xFFFE}));
}

TEST_P(ClientServer, ReadAndWriteLongerThanOneFrameAreSplitAndJoined) {
    ASSERT_NE(client, nullptr);
    std::vector<std::uint16_t> words(2500);
    std::iota(words.begin(), words.end(), std::uint16_t{1});
    ASSERT_TRUE(client->write_words(at("D1000"), words).has_value());
    auto r = client->read_words(at("D1000"), words.size());
    ASSERT_TRUE(r.has_value()) << r.error().message();
    EXPECT_EQ(*r, words);
}

TEST_P(ClientServer, ManyRequestsInFlightAllAnsweredBySid) {
    ASSERT_NE(client, nullptr);
    std::vector<std::uint16_t> words(200);
    std::iota(words.begin(), words.end(), std::uint16_t{500});
    ASSERT_TRUE(client->write_words(at("D0"), words).has_value());
    std::vector<int> got(words.size(), -1);
    for (std::uint16_t i = 0; i < words.size(); ++i) {
        client->async_send(MemoryAreaRead{{0x82, i, 0}, 1},
                           [&got, i](Result<MemoryAreaReadResponse> r) {
                               if (r && r->data.size() == 2)
                                   got[i] = (r->data[0] << 8) | r->data[1];
                           });
    }
    EXPECT_GT(client->in_flight(), 1u);
    client->run();
    for (std::size_t i = 0; i < words.size(); ++i)
        EXPECT_EQ(got[i], words[i]) << i;
}

TEST_P(ClientServer, FillTransferAndMultipleRead) {
    ASSERT_NE(client, nullptr);
    ASSERT_TRUE(client->fill(at("D300"), 10, 0xBEEF).has_value());
    ASSERT_TRUE(client->transfer(at("D300"), at("W100"), 10).has_value());
    auto w = client->read_words(at("W100"), 10);
    ASSERT_TRUE(w.has_value());
    EXPECT_EQ(*w, std::vector<std::uint16_t>(10, 0xBEEF));
    const std::vector<Address> items{at("W100"), at("W100.0"), at("T3"), at("IR2")};
    auto m = client->read_multiple(items);
    ASSERT_TRUE(m.has_value()) << m.error().message();
    EXPECT_EQ(*m, (std::vector<std::uint32_t>{0xBEEF, 1, 0, 0}));
}

// W342 5-1-3 end codes as a PLC answers them, through the whole stack.
TEST_P(ClientServer, EndCodesComeBackThroughTheStack) {
    ASSERT_NE(client, nullptr);
    EXPECT_EQ(raw({0x01, 0x01}, {0x99, 0, 0, 0, 0, 1}).code.raw(), 0x1101);        // no such area
    EXPECT_EQ(raw({0x01, 0x01}, {0x82, 0x80, 0, 0, 0, 1}).code.raw(), 0x1103);     // D32768
    EXPECT_EQ(raw({0x01, 0x01}, {0x82, 0x7F, 0xFF, 0, 0, 2}).code.raw(), 0x1104);  // D32767+1
    EXPECT_EQ(raw({0x01, 0x01}, {0x82, 0, 0, 0, 0x03, 0xE8}).code.raw(), 0x110B);  // 1000 words
    EXPECT_EQ(raw({0x01, 0x01}, {0x82, 0, 0, 0, 0}).code.raw(), 0x1002);
    EXPECT_EQ(raw({0x01, 0x01}, {0x82, 0, 0, 0, 0, 1, 0}).code.raw(), 0x1001);
    EXPECT_EQ(raw({0x01, 0x02}, {0x82, 0, 0, 0, 0, 2, 0, 1}).code.raw(), 0x1003);
    EXPECT_EQ(raw({0x01, 0x02}, {0xB3, 0, 10, 0, 0, 1, 0, 1}).code.raw(), 0x2101);  // A10
    EXPECT_EQ(raw({0x0F, 0x01}, {}).code.raw(), 0x0401);
    auto ok = raw({0x01, 0x01}, {0x82, 0, 0, 0, 0, 0});
    EXPECT_EQ(ok.code.raw(), 0x0000);  // W342 5-3-2 note 1: count 0 is normal, no data
    EXPECT_TRUE(ok.data.empty());
    // Typed send turns the end code into an error_code of the end-code category.
    auto typed = client->send(MemoryAreaRead{{0x82, 0x8000, 0}, 1});
    ASSERT_FALSE(typed.has_value());
    EXPECT_EQ(typed.error(), make_error_code(EndCode::address_range_error));
}

TEST_P(ClientServer, ResponseHeaderComesFromTheServerNode) {
    ASSERT_NE(client, nullptr);
    auto r = raw({0x01, 0x01}, {0x82, 0, 0, 0, 0, 1});
    EXPECT_EQ(r.header.source.node, server.address().node);
    EXPECT_EQ(r.header.destination, client->source());
    EXPECT_EQ(r.header.icf & 0x40, 0x40);
}

TEST_P(ClientServer, NoResponseModeWritesWithoutAnAnswer) {
    ASSERT_NE(client, nullptr);
    const std::vector<std::uint8_t> data{0x12, 0x34};
    ASSERT_TRUE(client->send_no_response(MemoryAreaWrite{{0x82, 42, 0}, 1, data}).has_value());
    // The next request on the same path is answered after the write was executed.
    auto r = client->read_words(at("D42"), 1);
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ((*r)[0], 0x1234);
}

TEST(ClientServerIpv6, UdpAndTcpOverLoopbackV6) {
    server::ServerOptions o;
    o.bind_address = "::1";
    std::unique_ptr<ServerThread> server;
    try {
        server = std::make_unique<ServerThread>(o);
    } catch (const std::exception& e) {
        GTEST_SKIP() << "no IPv6 loopback here: " << e.what();
    }
    for (bool tcp : {false, true}) {
        auto client = server->client(tcp);
        ASSERT_NE(client, nullptr);
        const std::vector<std::uint16_t> w{7, 8};
        ASSERT_TRUE(client->write_words(Address{Area::dm, 0, 5, {}}, w).has_value());
        EXPECT_EQ(client->read_words(Address{Area::dm, 0, 5, {}}, 2)
                      .value_or(std::vector<std::uint16_t>{}),
                  w);
    }
}

}  // namespace
}  // namespace fins::test
