// CPU UNIT DATA READ 05 01 and CONNECTION DATA READ 05 02 (W342 5-3-15, 5-3-16;
// frames 6/0501, 6/0502): round trips, exact response layouts, bad lengths.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/configuration.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

std::string text(const std::vector<std::uint8_t>& data, std::size_t offset, std::size_t n) {
    return std::string(data.begin() + static_cast<std::ptrdiff_t>(offset),
                       data.begin() + static_cast<std::ptrdiff_t>(offset + n));
}

CpuUnitDataReadResponse sample(std::optional<CpuUnitDataSection> section) {
    CpuUnitDataReadResponse r;
    r.section = section;
    if (r.has_model_and_area()) {
        r.model = "CJ2H-CPU68-EIP";
        r.system_version = "02.00";
        r.dip_switch = 0x01;
        r.largest_em_bank = 0x18;
        r.area = {500, 23, 32768, 8, 25, 0x04, 0x0800};
    }
    if (r.has_units_and_info()) {
        r.bus_units[0] = 0x8123;
        r.bus_units[15] = 0x8001;
        r.sysmac_bus_masters = 1;
        r.racks = 3;
    }
    return r;
}

TEST(CpuUnitDataRead, CommandVariants) {
    EXPECT_EQ(encode(CpuUnitDataRead{}), hex(""));
    EXPECT_EQ(encode(CpuUnitDataRead{CpuUnitDataSection::model_and_area}), hex("00"));
    EXPECT_EQ(encode(CpuUnitDataRead{CpuUnitDataSection::units_and_info}), hex("01"));
    EXPECT_FALSE(CpuUnitDataRead::decode({})->section);
    EXPECT_EQ(CpuUnitDataRead::decode(hex("01"))->section, CpuUnitDataSection::units_and_info);
    EXPECT_EQ(CpuUnitDataRead::decode(hex("00 00")).error(), EndCode::command_too_long);
    EXPECT_EQ(CpuUnitDataRead::decode(hex("02")).error(), EndCode::parameter_error);
}

// W342 5-3-15: the SYSMAC BUS master count "is returned in a single byte", so the
// full answer is 158 data bytes (160 with the end code), as real CS/CJ/CP units send.
TEST(CpuUnitDataRead, W342_5_3_15_FullResponseIs158DataBytesRemoteIoInASingleByte) {
    const auto r = sample(std::nullopt);
    const auto data = encode(r);
    ASSERT_EQ(data.size(), 158U);
    // Model: 20 bytes space padded; version: 20 bytes NUL padded.
    EXPECT_EQ(text(data, 0, 20), "CJ2H-CPU68-EIP      ");
    EXPECT_EQ(data[20], '0');
    EXPECT_EQ(data[24], '0');
    EXPECT_EQ(data[25], 0x00);
    EXPECT_EQ(data[39], 0x00);
    // System use: DIP switch, largest EM bank, then 38 zero bytes.
    EXPECT_EQ(data[40], 0x01);
    EXPECT_EQ(data[41], 0x18);
    // Area data at 80: program size, IOM, DM words, T/C, EM, 2 unused, card type, size.
    EXPECT_EQ(std::vector<std::uint8_t>(data.begin() + 80, data.begin() + 92),
              hex("01F4 17 8000 08 19 0000 04 0800"));
    // CPU Bus Unit words at 92, unit 15 at 122; 32 reserved bytes; remote I/O (one
    // byte: the master count); CPU information (racks) last.
    EXPECT_EQ(data[92], 0x81);
    EXPECT_EQ(data[93], 0x23);
    EXPECT_EQ(data[122], 0x80);
    EXPECT_EQ(data[123], 0x01);
    EXPECT_EQ(data[156], 0x01);
    EXPECT_EQ(data[157], 0x03);

    const CpuUnitDataRead command;
    const auto d = command.decode_response(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, r);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(command.decode_response(prefix(data, n))) << n;
    auto longer = data;
    longer.insert(longer.begin() + 156, 0x00);
    longer.push_back(0);  // 160: neither layout
    EXPECT_FALSE(command.decode_response(longer));
}

// The client also reads the CV-series layout (a 2-byte remote I/O field "always 00"
// then the count, 159 data bytes, Wireshark's dissector), CPU information last.
TEST(CpuUnitDataRead, ClientAcceptsTheCvSeriesTwoByteRemoteIoLayout) {
    auto data = encode(sample(std::nullopt));
    data.insert(data.begin() + 156, 0x00);  // the CV "always 00" byte
    ASSERT_EQ(data.size(), 159U);
    const auto d = CpuUnitDataRead{}.decode_response(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->sysmac_bus_masters, 1);
    EXPECT_EQ(d->racks, 3);
    EXPECT_EQ(*d, sample(std::nullopt));
    auto units = encode(sample(CpuUnitDataSection::units_and_info));
    units.insert(units.begin() + 64, 0x00);
    const CpuUnitDataRead selector01{CpuUnitDataSection::units_and_info};
    ASSERT_TRUE(selector01.decode_response(units));
    EXPECT_EQ(selector01.decode_response(units)->racks, 3);
}

TEST(CpuUnitDataRead, W342_5_3_15_SelectorsReturnTheirParts) {
    for (auto section : {CpuUnitDataSection::model_and_area, CpuUnitDataSection::units_and_info}) {
        const auto r = sample(section);
        const auto data = encode(r);
        EXPECT_EQ(data.size(), section == CpuUnitDataSection::model_and_area ? 92U : 66U);
        const CpuUnitDataRead command{section};
        const auto d = command.decode_response(data);
        ASSERT_TRUE(d);
        EXPECT_EQ(*d, r);
        for (std::size_t n = 0; n < data.size(); ++n)
            EXPECT_FALSE(command.decode_response(prefix(data, n))) << n;
    }
}

TEST(ConnectionDataRead, CommandVariants) {
    EXPECT_EQ(encode(ConnectionDataRead{0x10, std::nullopt}), hex("10"));
    EXPECT_EQ(encode(ConnectionDataRead{0x00, 0x19}), hex("00 19"));
    const auto d = ConnectionDataRead::decode(hex("10"));
    ASSERT_TRUE(d);
    EXPECT_EQ(d->first_unit, 0x10);
    EXPECT_EQ(d->items(), 25);  // 5-3-16: omitted -> 19 hex
    EXPECT_EQ(ConnectionDataRead::decode(hex("00 05"))->count, 5);
    EXPECT_EQ(ConnectionDataRead::decode({}).error(), EndCode::command_too_short);
    EXPECT_EQ(ConnectionDataRead::decode(hex("00 01 00")).error(), EndCode::command_too_long);
}

TEST(ConnectionDataRead, W342_5_3_16_CountMustBe01To19) {
    EXPECT_EQ(ConnectionDataRead::decode(hex("00 00")).error(), EndCode::parameter_error);
    EXPECT_EQ(ConnectionDataRead::decode(hex("00 1A")).error(), EndCode::parameter_error);
    EXPECT_TRUE(ConnectionDataRead::decode(hex("00 01")));
    EXPECT_TRUE(ConnectionDataRead::decode(hex("00 19")));
}

TEST(ConnectionDataRead, ResponseRoundTripAndLengths) {
    ConnectionDataReadResponse r;
    r.last_unit_included = true;
    r.units = {{0x00, "CJ2H-CPU68-EIP"}, {0x11, "CJ1W-ETN21"}};
    const auto data = encode(r);
    ASSERT_EQ(data.size(), 1U + 2 * 21);
    EXPECT_EQ(data[0], 0x82);  // 2 units, bit 7: the last unit is included
    EXPECT_EQ(data[22], 0x11);
    EXPECT_EQ(text(data, 23, 20), "CJ1W-ETN21          ");
    const ConnectionDataRead command{0x00, 2};
    const auto d = command.decode_response(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, r);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(command.decode_response(prefix(data, n))) << n;
    // More units than asked for is not an answer to this request.
    EXPECT_FALSE((ConnectionDataRead{0x00, 1}.decode_response(data)));
    // No units: just the count byte.
    EXPECT_TRUE((ConnectionDataRead{0xE2, 1}.decode_response(hex("80"))));
}

}  // namespace
}  // namespace fins
