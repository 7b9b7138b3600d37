// Client I/O memory helpers over UDP against the in-test responder: splitting and
// joining long reads/writes, bits, fill, transfer, multiple read, typed values.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "client/loopback_servers.hpp"
#include "fins/client.hpp"
#include "fins/commands/memory_area.hpp"

using namespace fins;
using namespace fins::test;

namespace {

class Helpers : public ::testing::Test {
  protected:
    void SetUp() override {
        ClientOptions options;
        options.port = server.port();
        auto c = Client::connect(options);
        ASSERT_TRUE(c);
        client = std::move(*c);
    }

    // Decoded MEMORY AREA READ/WRITE parameters of every request the server saw.
    std::vector<std::pair<MemoryAddress, std::uint16_t>> requested() {
        std::vector<std::pair<MemoryAddress, std::uint16_t>> out;
        for (const auto& frame : server.requests()) {
            auto req = decode_request(frame);
            ByteReader r(req->parameters);
            MemoryAddress a{r.u8(), r.u16(), r.u8()};
            out.emplace_back(a, r.u16());
        }
        return out;
    }

    UdpResponder server;
    std::unique_ptr<Client> client;
};

Address dm(std::uint16_t word) {
    return Address{Area::dm, 0, word, std::nullopt};
}
Address dm_bit(std::uint16_t word, std::uint8_t bit) {
    return Address{Area::dm, 0, word, bit};
}

TEST_F(Helpers, ReadOf2000WordsIsThreeRequestsInFlightTogether) {
    server.hold_until(3);  // answers nothing until all three parts have arrived
    server.with_plc([](FakePlc& plc) {
        for (std::uint16_t i = 0; i < 2100; ++i)
            plc.dm[i] = static_cast<std::uint16_t>(i * 3);
    });
    auto words = client->read_words(dm(50), 2000);
    ASSERT_TRUE(words) << words.error().message();
    ASSERT_EQ(words->size(), 2000u);
    for (std::uint16_t i = 0; i < 2000; ++i)
        ASSERT_EQ((*words)[i], static_cast<std::uint16_t>((50 + i) * 3));
    auto parts = requested();
    ASSERT_EQ(parts.size(), 3u);
    EXPECT_EQ(parts[0].first.word, 50);
    EXPECT_EQ(parts[0].second, 999);
    EXPECT_EQ(parts[1].first.word, 50 + 999);
    EXPECT_EQ(parts[1].second, 999);
    EXPECT_EQ(parts[2].first.word, 50 + 1998);
    EXPECT_EQ(parts[2].second, 2);
}

TEST_F(Helpers, ASplitReadFailsAsAWholeWhenOnePartFails) {
    server.with_plc([](FakePlc& plc) { plc.fail_word = 999; });
    auto words = client->read_words(dm(0), 2000);
    ASSERT_FALSE(words);
    EXPECT_EQ(words.error(), make_error_code(EndCode::address_range_error));
    EXPECT_EQ(server.requests().size(), 3u) << "all parts were sent";
    EXPECT_EQ(client->in_flight(), 0u);
}

TEST_F(Helpers, WriteOf2000WordsIsThreeRequests) {
    std::vector<std::uint16_t> words(2000);
    for (std::size_t i = 0; i < words.size(); ++i)
        words[i] = static_cast<std::uint16_t>(i + 1);
    ASSERT_TRUE(client->write_words(dm(100), words));
    auto parts = requested();
    ASSERT_EQ(parts.size(), 3u);
    EXPECT_EQ(parts[0].second, 997);
    EXPECT_EQ(parts[1].first.word, 100 + 997);
    EXPECT_EQ(parts[1].second, 997);
    EXPECT_EQ(parts[2].second, 6);
    server.with_plc([](FakePlc& plc) {
        for (std::uint16_t i = 0; i < 2000; ++i)
            ASSERT_EQ(plc.dm[100 + i], i + 1) << i;
        EXPECT_EQ(plc.dm[2100], 0);
    });
}

TEST_F(Helpers, ZeroWordsSendsNothing) {
    auto words = client->read_words(dm(0), 0);
    ASSERT_TRUE(words);
    EXPECT_TRUE(words->empty());
    EXPECT_TRUE(client->write_words(dm(0), {}));
    EXPECT_TRUE(server.requests().empty());
}

TEST_F(Helpers, WordHelpersRefuseBitAddresses) {
    auto r = client->read_words(dm_bit(0, 1), 1);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(AddressError::bit_not_allowed));
}

TEST_F(Helpers, BitsStepAcrossWordBoundaries) {
    ASSERT_TRUE(client->write_bits(dm_bit(10, 14), {true, false, true, true}));
    server.with_plc([](FakePlc& plc) {
        EXPECT_EQ(plc.dm[10], 0x4000);
        EXPECT_EQ(plc.dm[11], 0x0003);
    });
    auto bits = client->read_bits(dm_bit(10, 14), 4);
    ASSERT_TRUE(bits);
    EXPECT_EQ(*bits, (std::vector<bool>{true, false, true, true}));
}

TEST_F(Helpers, LongBitReadIsSplitOnBitBoundaries) {
    server.with_plc([](FakePlc& plc) { plc.cio[62] = 0x0080; });  // CIO 62.07 = bit 999
    auto bits = client->read_bits(Address{Area::cio, 0, 0, std::uint8_t{0}}, 1500);
    ASSERT_TRUE(bits) << bits.error().message();
    auto parts = requested();
    ASSERT_EQ(parts.size(), 2u);
    EXPECT_EQ(parts[1].first.word, 62);
    EXPECT_EQ(parts[1].first.bit, 7);
    EXPECT_EQ(parts[1].second, 501);
    for (std::size_t i = 0; i < bits->size(); ++i)
        ASSERT_EQ((*bits)[i], i == 999) << i;
}

TEST_F(Helpers, FillAndTransfer) {
    ASSERT_TRUE(client->fill(dm(200), 5, 0xAAAA));
    ASSERT_TRUE(client->transfer(dm(200), dm(300), 5));
    server.with_plc([](FakePlc& plc) {
        for (std::size_t i = 0; i < 5; ++i)
            EXPECT_EQ(plc.dm[300 + i], 0xAAAA);
        EXPECT_EQ(plc.dm[305], 0);
    });
}

TEST_F(Helpers, ReadMultipleSplitsAt167Items) {
    server.with_plc([](FakePlc& plc) {
        for (std::uint16_t i = 0; i < 200; ++i)
            plc.dm[i] = static_cast<std::uint16_t>(i + 7);
    });
    std::vector<Address> addresses;
    for (std::uint16_t i = 0; i < 200; ++i)
        addresses.push_back(dm(i));
    auto values = client->read_multiple(addresses);
    ASSERT_TRUE(values) << values.error().message();
    ASSERT_EQ(values->size(), 200u);
    for (std::uint16_t i = 0; i < 200; ++i)
        EXPECT_EQ((*values)[i], i + 7u);
    EXPECT_EQ(server.requests().size(), 2u);
}

TEST_F(Helpers, TypedValuesUseOmronWordOrder) {
    ASSERT_TRUE(client->write_int32(dm(0), 0x12345678));
    server.with_plc([](FakePlc& plc) {
        EXPECT_EQ(plc.dm[0], 0x5678) << "least significant word first";
        EXPECT_EQ(plc.dm[1], 0x1234);
    });
    EXPECT_EQ(client->read_int32(dm(0)).value_or(0), 0x12345678);
    ASSERT_TRUE(client->write_int16(dm(2), -2));
    EXPECT_EQ(client->read_int16(dm(2)).value_or(0), -2);
    EXPECT_EQ(client->read_uint16(dm(2)).value_or(0), 0xFFFE);
    ASSERT_TRUE(client->write_uint32(dm(4), 0xDEADBEEF));
    EXPECT_EQ(client->read_uint32(dm(4)).value_or(0), 0xDEADBEEFu);
    ASSERT_TRUE(client->write_float(dm(6), 1.0f));
    server.with_plc([](FakePlc& plc) {
        EXPECT_EQ(plc.dm[6], 0x0000);
        EXPECT_EQ(plc.dm[7], 0x3F80);
    });
    EXPECT_EQ(client->read_float(dm(6)).value_or(0.0f), 1.0f);
    ASSERT_TRUE(client->write_double(dm(8), -2.5));
    EXPECT_EQ(client->read_double(dm(8)).value_or(0.0), -2.5);
    ASSERT_TRUE(client->write_uint16(dm(12), 0x0102));
    EXPECT_EQ(client->read_uint16(dm(12)).value_or(0), 0x0102);
}

TEST_F(Helpers, BcdAndStrings) {
    ASSERT_TRUE(client->write_bcd16(dm(20), 1234));
    server.with_plc([](FakePlc& plc) { EXPECT_EQ(plc.dm[20], 0x1234); });
    EXPECT_EQ(client->read_bcd16(dm(20)).value_or(0), 1234);
    ASSERT_TRUE(client->write_bcd32(dm(22), 12345678));
    EXPECT_EQ(client->read_bcd32(dm(22)).value_or(0), 12345678u);
    auto bad = client->write_bcd16(dm(20), 10000);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(), make_error_code(ClientError::invalid_argument));
    server.with_plc([](FakePlc& plc) { plc.dm[24] = 0x00AB; });
    EXPECT_FALSE(client->read_bcd16(dm(24))) << "A-F nibbles are not BCD";

    ASSERT_TRUE(client->write_string(dm(30), "HELLO", 4));
    server.with_plc([](FakePlc& plc) {
        EXPECT_EQ(plc.dm[30], 0x4845);  // 'H' 'E': first character in the high byte
        EXPECT_EQ(plc.dm[32], 0x4F00);
        EXPECT_EQ(plc.dm[33], 0x0000);
    });
    EXPECT_EQ(client->read_string(dm(30), 4).value_or(""), "HELLO");
    ASSERT_TRUE(client->write_string(dm(40), "ABC"));
    EXPECT_EQ(client->read_string(dm(40), 2).value_or(""), "ABC");
}

}  // namespace
