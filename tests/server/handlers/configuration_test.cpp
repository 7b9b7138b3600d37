// CPU UNIT DATA READ 05 01 and CONNECTION DATA READ 05 02 through the dispatcher with
// full frames (W342 5-3-15, 5-3-16; W596 2-2 NX fixed values).
#include <fmt/core.h>
#include <gtest/gtest.h>

#include "fins/commands/configuration.hpp"
#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

plc::Profile with_units() {
    plc::Profile p = plc::cj2h();
    p.model = "CJ2H-CPU68-EIP";
    p.system_version = "01.90";
    p.program_kwords = 800;
    p.em_banks = 25;
    p.memory_card_type = 0x04;
    p.memory_card_kbytes = 0x0800;
    p.racks = 2;
    p.dip_switch = 0x00;
    p.units = {{0x10, "CJ1W-ETN21", 0x0123},
               {0x1F, "CJ1W-CLK23", 0x0045},
               {0x20, "CJ1W-AD081-V1", 0},
               {0xE1, "CJ1W-SCB41-V1", 0}};
    return p;
}

std::string ascii(const std::vector<std::uint8_t>& d, std::size_t offset, std::size_t n) {
    return std::string(d.begin() + static_cast<std::ptrdiff_t>(offset),
                       d.begin() + static_cast<std::ptrdiff_t>(offset + n));
}

// W342 5-3-15: remote I/O data "is returned in a single byte": 158 data bytes after
// the end code, as real CS/CJ/CP CPU Units answer (and libfins requires).
TEST(CpuUnitDataReadHandler, W342_5_3_15_AllDataIs158BytesAfterTheEndCode) {
    Harness h(with_units());
    const auto r = h.send("0501");
    ASSERT_EQ(r.end_code(), 0x0000);
    const auto d = r.data();
    ASSERT_EQ(d.size(), 158U);
    EXPECT_EQ(r.frame.size(), header_size + 2 + 2 + 158);
    EXPECT_EQ(ascii(d, 0, 20), "CJ2H-CPU68-EIP      ");
    EXPECT_EQ(ascii(d, 20, 5), "01.90");
    EXPECT_EQ(d[25], 0x00);  // version padded with NULs
    EXPECT_EQ(d[40], 0x00);  // DIP switch
    EXPECT_EQ(d[41], 0x18);  // largest EM bank: 24
    EXPECT_EQ(to_hex(Bytes(d).subspan(80, 12)), "03 20 17 80 00 08 19 00 00 04 08 00");
    // CPU Bus Unit 0 (unit address 10) and 15 (1F); the Special I/O Unit is not one.
    EXPECT_EQ(to_hex(Bytes(d).subspan(92, 4)), "81 23 00 00");
    EXPECT_EQ(to_hex(Bytes(d).subspan(122, 2)), "80 45");
    EXPECT_EQ(to_hex(Bytes(d).subspan(156, 2)), "00 02");  // remote I/O 00, 2 racks
    // The client decodes what the server sent.
    const auto decoded = CpuUnitDataRead{}.decode_response(d);
    ASSERT_TRUE(decoded);
    EXPECT_EQ(decoded->model, "CJ2H-CPU68-EIP");
    EXPECT_EQ(decoded->area.program_kwords, 800);
    EXPECT_EQ(decoded->racks, 2);
}

TEST(CpuUnitDataReadHandler, W342_5_3_15_SelectorsReturnTheirParts) {
    Harness h(with_units());
    const auto all = h.send("0501").data();
    const auto area = h.send("0501 00");
    ASSERT_EQ(area.end_code(), 0x0000);
    EXPECT_EQ(area.data(), std::vector<std::uint8_t>(all.begin(), all.begin() + 92));
    const auto units = h.send("0501 01");
    ASSERT_EQ(units.end_code(), 0x0000);
    EXPECT_EQ(units.data(), std::vector<std::uint8_t>(all.begin() + 92, all.end()));
}

TEST(CpuUnitDataReadHandler, W342_5_3_15_BadSelectorAndLength) {
    Harness h;
    EXPECT_EQ(h.send("0501 02").end_code(), 0x110C);
    EXPECT_EQ(h.send("0501 FF").end_code(), 0x110C);
    EXPECT_EQ(h.send("0501 00 00").end_code(), 0x1001);
}

TEST(CpuUnitDataReadHandler, W342_5_3_15_DipSwitchPin1FollowsUmWriteProtection) {
    Harness h;
    h.plc.set_dip_write_protection(true);
    const auto r = h.send("0501 00");
    ASSERT_EQ(r.end_code(), 0x0000);  // 5-1-2: accepted under every protection
    EXPECT_EQ(r.data()[40], 0x01);
}

TEST(CpuUnitDataReadHandler, W342_5_1_2_AcceptedInEveryMode) {
    Harness h;
    h.plc.set_mode(plc::OperatingMode::program);
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    h.plc.set_network_write_protection(true);
    h.plc.set_um_read_protection(true);
    EXPECT_EQ(h.send("0501").end_code(), 0x0000);
    EXPECT_EQ(h.send("0502 00").end_code(), 0x0000);
}

TEST(CpuUnitDataReadHandler, W596_2_2_NxReturnsFixedValues) {
    plc::Profile p = with_units();
    p.model = "NX102-9000";
    p.nx_fixed_values = true;
    p.dip_switch = 0xFF;
    p.program_kwords = 999;
    p.timer_counter_kwords = 3;
    p.memory_card_type = 0x00;
    p.memory_card_kbytes = 0x1234;  // a card is inserted
    Harness h(p);
    auto d = h.send("0501").data();
    ASSERT_EQ(d.size(), 158U);
    EXPECT_EQ(ascii(d, 0, 10), "NX102-9000");
    EXPECT_EQ(d[40], 0x00);                                  // DIP switch: 0
    EXPECT_EQ(to_hex(Bytes(d).subspan(80, 2)), "00 14");     // program area: 14 hex
    EXPECT_EQ(d[85], 0x08);                                  // timer/counter: 08
    EXPECT_EQ(to_hex(Bytes(d).subspan(89, 3)), "04 FF FF");  // SD card, inserted
    EXPECT_EQ(d[156], 0x00);                                 // remote I/O: 0

    p.memory_card_kbytes = 0;  // no card
    Harness without(p);
    d = without.send("0501").data();
    EXPECT_EQ(to_hex(Bytes(d).subspan(89, 3)), "04 00 00");
}

// W342 5-3-15 "Memory card type 00: No memory card", "Memory card size ... 0000 if
// there is no memory card": type and size agree on every CS/CJ/CP profile.
TEST(CpuUnitDataReadHandler, W342_5_3_15_NoCardIsType00Size0000ACardItsTypeAndSize) {
    plc::Profile p = with_units();
    p.memory_card_type = 0x04;
    p.memory_card_kbytes = 0;  // a type but no size: no card
    Harness without(p);
    EXPECT_EQ(to_hex(Bytes(without.send("0501 00").data()).subspan(89, 3)), "00 00 00");
    for (const auto& profile : plc::profiles()) {
        if (profile.nx_fixed_values) continue;
        SCOPED_TRACE(profile.name);
        Harness h(profile);
        const auto d = h.send("0501 00").data();
        const bool card = d[89] != 0x00;
        EXPECT_EQ(card, d[90] != 0x00 || d[91] != 0x00);
        EXPECT_EQ(card, profile.memory_card_kbytes != 0);
        if (card) {
            EXPECT_EQ(d[89], 0x04);  // flash memory
            EXPECT_EQ((d[90] << 8) | d[91], profile.memory_card_kbytes);
        }
    }
    // The CS1H profile's 30 MB flash card.
    Harness cs1h(*plc::find_profile("cs1h"));
    EXPECT_EQ(to_hex(Bytes(cs1h.send("0501 00").data()).subspan(89, 3)), "04 78 00");
}

// 11a: program area size = twice the catalogue K steps, as real units report it;
// model strings with an underscore on CS1/CJ1/CP1, hyphens on CJ2 (profile.cpp).
TEST(CpuUnitDataReadHandler, RealUnitsProgramAreaSizeAndModelStrings) {
    const struct {
        const char* profile;
        const char* model;
        const char* version;
        const char* program_area;
    } expected[] = {
        {"cj2h", "CJ2H-CPU68-EIP", "01.90", "03 20"},  // 400K steps
        {"cs1h", "CS1H_CPU67H", "04.00", "01 F4"},     // 250K steps
        {"cj1m", "CJ1M_CPU13", "04.10", "00 28"},      // 20K steps
        {"cp1h", "CP1H_XA40DR-A", "01.00", "00 28"},   // 20K steps
    };
    for (const auto& e : expected) {
        SCOPED_TRACE(e.profile);
        Harness h(*plc::find_profile(e.profile));
        const auto d = h.send("0501 00").data();
        ASSERT_EQ(d.size(), 92U);
        EXPECT_EQ(ascii(d, 0, 20), fmt::format("{:<20}", e.model));
        EXPECT_EQ(ascii(d, 20, 5), e.version);
        EXPECT_EQ(to_hex(Bytes(d).subspan(80, 2)), e.program_area);
    }
}

// A unit 05 02 lists is present (not 0202). A CPU Bus Unit answers its own 05 01
// CONTROLLER DATA READ (W421 7-3-2: model, version, IP address, subnet mask, FINS UDP
// port, mode setting, Ethernet address) and 0401 to everything else; so do the other
// listed units (Special I/O Units, Inner Boards other than the Loop Control Board).
TEST(UnitPresence, ListedUnitsArePresentCpuBusUnitAnswersItsControllerData) {
    Harness h(with_units());
    FrameFields to;
    to.destination.unit = 0x10;
    const auto r = h.send("0501", to);
    ASSERT_EQ(r.end_code() & 0x7F3F, 0x0000);
    EXPECT_EQ(r.header().source.unit, 0x10);
    const auto d = r.data();
    ASSERT_EQ(d.size(), 58U);
    EXPECT_EQ(ascii(d, 0, 20), "CJ1W-ETN21          ");
    EXPECT_EQ(ascii(d, 20, 20), fmt::format("{:<20}", "V1.00"));
    EXPECT_EQ(to_hex(Bytes(d).subspan(40, 18)),
              "00 00 00 00 00 00 00 00 25 80 00 00 00 00 00 00 00 00");
    EXPECT_EQ(h.send("0501 00", to).end_code(), 0x1001);
    EXPECT_EQ(h.send("0101 82000000 0001", to).end_code(), 0x0401);
    EXPECT_EQ(h.send("0502 00", to).end_code(), 0x0401);
    for (std::uint8_t unit : {std::uint8_t{0x1F}, std::uint8_t{0x20}, std::uint8_t{0xE1}}) {
        FrameFields other;
        other.destination.unit = unit;
        EXPECT_EQ(h.send("0101 82000000 0001", other).end_code(), 0x0401) << int{unit};
        EXPECT_EQ(h.send("0501", other).end_code(), unit == 0x1F ? 0x0000 : 0x0401) << int{unit};
    }
    // Unlisted units are missing.
    for (std::uint8_t unit : {std::uint8_t{0x11}, std::uint8_t{0x21}, std::uint8_t{0xFE}}) {
        FrameFields missing;
        missing.destination.unit = unit;
        EXPECT_EQ(h.send("0501", missing).end_code(), 0x0202) << int{unit};
    }
    // The default profile's built-in EtherNet/IP port (unit 10).
    Harness cj2h;
    const auto port = cj2h.send("0501", to);
    EXPECT_EQ(port.end_code() & 0x7F3F, 0x0000);
    EXPECT_EQ(ascii(port.data(), 0, 10), "CJ2B-EIP21");
}

TEST(ConnectionDataReadHandler, W342_5_3_16_AllUnitsFromTheCpuUnit) {
    Harness h(with_units());
    const auto r = h.send("0502 00");
    ASSERT_EQ(r.end_code(), 0x0000);
    const auto d = r.data();
    ASSERT_EQ(d.size(), 1U + 5 * 21);
    EXPECT_EQ(d[0], 0x85);  // 5 units, bit 7: the last one is included
    EXPECT_EQ(d[1], 0x00);
    EXPECT_EQ(ascii(d, 2, 20), "CJ2H-CPU68-EIP      ");
    EXPECT_EQ(d[22], 0x10);
    EXPECT_EQ(ascii(d, 23, 20), "CJ1W-ETN21          ");
    EXPECT_EQ(d[43], 0x1F);
    EXPECT_EQ(d[64], 0x20);
    EXPECT_EQ(d[85], 0xE1);
    const auto decoded = ConnectionDataRead{0x00, std::nullopt}.decode_response(d);
    ASSERT_TRUE(decoded);
    EXPECT_TRUE(decoded->last_unit_included);
    EXPECT_EQ(decoded->units.size(), 5U);
}

TEST(ConnectionDataReadHandler, W342_5_3_16_CountLimitsAndBit7) {
    Harness h(with_units());
    auto d = h.send("0502 00 02").data();
    ASSERT_EQ(d.size(), 1U + 2 * 21);
    EXPECT_EQ(d[0], 0x02);  // more units follow: bit 7 off
    EXPECT_EQ(d[22], 0x10);
    d = h.send("0502 20 02").data();
    EXPECT_EQ(d[0], 0x82);  // 20 and E1: E1 is the last unit
}

TEST(ConnectionDataReadHandler, W342_5_3_16_MissingUnitReadsFromTheNextOne) {
    Harness h(with_units());
    auto d = h.send("0502 05 01").data();
    ASSERT_EQ(d.size(), 22U);
    EXPECT_EQ(d[0], 0x01);
    EXPECT_EQ(d[1], 0x10);
    d = h.send("0502 21").data();
    ASSERT_EQ(d.size(), 22U);
    EXPECT_EQ(d[0], 0x81);
    EXPECT_EQ(d[1], 0xE1);
}

TEST(ConnectionDataReadHandler, W342_5_3_16_PastTheLastUnitAnswersNoUnits) {
    Harness h(with_units());
    const auto r = h.send("0502 E2");
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "80");
    // A CPU Unit alone: itself, and it is the last unit.
    plc::Profile alone = plc::cj2h();
    alone.units.clear();
    Harness bare(alone);
    const auto d = bare.send("0502 00").data();
    ASSERT_EQ(d.size(), 22U);
    EXPECT_EQ(d[0], 0x81);
    EXPECT_EQ(d[1], 0x00);
}

TEST(ConnectionDataReadHandler, W342_5_3_16_BadCountAndLengths) {
    Harness h;
    EXPECT_EQ(h.send("0502 00 00").end_code(), 0x110C);
    EXPECT_EQ(h.send("0502 00 1A").end_code(), 0x110C);
    EXPECT_EQ(h.send("0502").end_code(), 0x1002);
    EXPECT_EQ(h.send("0502 00 01 00").end_code(), 0x1001);
    EXPECT_EQ(h.send("0502 00 19").end_code(), 0x0000);
}

}  // namespace
}  // namespace fins::test
