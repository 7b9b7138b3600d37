// PLC address strings (fins/address.hpp) and their FINS memory addresses (W342 5-2-2).
#include <sstream>

#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/address.hpp"
#include "fins/address_names.hpp"

namespace fins {
namespace {

struct Form {
    std::string_view text;
    std::string_view canonical;
    Address address;
};

const Form forms[] = {
    {"D100", "D100", {Area::dm, 0, 100, std::nullopt}},
    {"D100.15", "D100.15", {Area::dm, 0, 100, 15}},
    {"CIO10.13", "CIO10.13", {Area::cio, 0, 10, 13}},
    {"10.13", "CIO10.13", {Area::cio, 0, 10, 13}},
    {"10", "CIO10", {Area::cio, 0, 10, std::nullopt}},
    {"W5", "W5", {Area::work, 0, 5, std::nullopt}},
    {"H10.1", "H10.01", {Area::holding, 0, 10, 1}},
    {"h10.01", "H10.01", {Area::holding, 0, 10, 1}},
    {"A448", "A448", {Area::auxiliary, 0, 448, std::nullopt}},
    {"T10", "T10", {Area::timer, 0, 10, std::nullopt}},
    {"C10", "C10", {Area::counter, 0, 10, std::nullopt}},
    {"E3_100", "E3_100", {Area::em, 3, 100, std::nullopt}},
    {"E10_5", "E10_5", {Area::em, 0x10, 5, std::nullopt}},
    {"ea_7", "EA_7", {Area::em, 0x0A, 7, std::nullopt}},
    {"E18_32767.15", "E18_32767.15", {Area::em, 0x18, 32767, 15}},
    {"E0_0.5", "E0_0.05", {Area::em, 0, 0, 5}},
    {"E100", "E100", {Area::em_current, 0, 100, std::nullopt}},
    {"E100.3", "E100.03", {Area::em_current, 0, 100, 3}},
    {"IR0", "IR0", {Area::index_register, 0, 0, std::nullopt}},
    {"ir15", "IR15", {Area::index_register, 0, 15, std::nullopt}},
    {"DR3", "DR3", {Area::data_register, 0, 3, std::nullopt}},
    {"TK2", "TK2", {Area::task_flag, 0, 2, std::nullopt}},
    {"tk31", "TK31", {Area::task_flag, 0, 31, std::nullopt}},
    {"cio6143.15", "CIO6143.15", {Area::cio, 0, 6143, 15}},
    {"D00100", "D100", {Area::dm, 0, 100, std::nullopt}},
    {"d32767", "D32767", {Area::dm, 0, 32767, std::nullopt}},
    {"W511.15", "W511.15", {Area::work, 0, 511, 15}},
    {"A959", "A959", {Area::auxiliary, 0, 959, std::nullopt}},
    {"C4095", "C4095", {Area::counter, 0, 4095, std::nullopt}},
    // Bit numbers print with two digits, as Omron writes them (CIO 0.00 to 0.15, W342
    // 5-2-2 and CX-Programmer); both forms parse.
    {"CIO0.0", "CIO0.00", {Area::cio, 0, 0, 0}},
    {"CIO0.00", "CIO0.00", {Area::cio, 0, 0, 0}},
    {"W3.7", "W3.07", {Area::work, 0, 3, 7}},
    {"W3.07", "W3.07", {Area::work, 0, 3, 7}},
    {"E3_200.5", "E3_200.05", {Area::em, 3, 200, 5}},
    {"A448.10", "A448.10", {Area::auxiliary, 0, 448, 10}},
};

TEST(Address, ParseFormatRoundTrip) {
    for (const auto& f : forms) {
        SCOPED_TRACE(std::string(f.text));
        auto a = parse_address(f.text);
        ASSERT_TRUE(a) << a.error().message();
        EXPECT_EQ(*a, f.address);
        EXPECT_EQ(format_address(*a), f.canonical);
        auto again = parse_address(format_address(*a));
        ASSERT_TRUE(again);
        EXPECT_EQ(*again, *a);
    }
}

struct Bad {
    std::string_view text;
    AddressError error;
};

TEST(Address, BadStrings) {
    const Bad cases[] = {
        {"", AddressError::empty},
        {" D100", AddressError::unknown_area},         // no leading spaces
        {"D100 ", AddressError::trailing_characters},  // no trailing spaces
        {"X100", AddressError::unknown_area},
        {"LR5", AddressError::unknown_area},  // LR is CIO 1000-1199: no single area
        {"DMX", AddressError::bad_number},
        {"TIM5.1", AddressError::bit_not_allowed},
        {"D", AddressError::bad_number},
        {"D-1", AddressError::bad_number},
        {"D+1", AddressError::bad_number},
        {"D100.", AddressError::bad_number},
        {"D100.16", AddressError::bit_out_of_range},
        {"D100.999", AddressError::bit_out_of_range},
        {"D32768", AddressError::word_out_of_range},
        {"D99999999999999999999", AddressError::word_out_of_range},
        {"CIO6144", AddressError::word_out_of_range},
        {"6144", AddressError::word_out_of_range},
        {"W512", AddressError::word_out_of_range},
        {"H512.0", AddressError::word_out_of_range},
        {"A960", AddressError::word_out_of_range},
        {"T4096", AddressError::word_out_of_range},
        {"C4096", AddressError::word_out_of_range},
        {"IR16", AddressError::word_out_of_range},
        {"DR16", AddressError::word_out_of_range},
        {"TK32", AddressError::word_out_of_range},
        {"E19_0", AddressError::bank_out_of_range},
        {"E100_0", AddressError::bank_out_of_range},
        {"E_5", AddressError::bad_number},
        {"EG_5", AddressError::bad_number},
        {"E3_", AddressError::bad_number},
        {"E3_x", AddressError::bad_number},
        {"E32768", AddressError::word_out_of_range},
        {"IR0.1", AddressError::bit_not_allowed},
        {"DR3.0", AddressError::bit_not_allowed},
        {"T10.1", AddressError::bit_not_allowed},
        {"C10.1", AddressError::bit_not_allowed},
        {"TK2.1", AddressError::bit_not_allowed},
        {"D100x", AddressError::trailing_characters},
        {"D100.1.2", AddressError::trailing_characters},
        {"D1 00", AddressError::trailing_characters},
        {"CIO 10", AddressError::bad_number},
        {"10.13\n", AddressError::trailing_characters},
        {".5", AddressError::unknown_area},
    };
    for (const auto& c : cases) {
        auto a = parse_address(c.text);
        ASSERT_FALSE(a) << "'" << c.text << "' parsed";
        EXPECT_EQ(a.error(), make_error_code(c.error)) << "'" << c.text << "'";
    }
}

// W342 5-2-2 names the areas D, H, W, A, T, C; CX-Programmer and the older manuals call
// them DM, HR, WR, AR, TIM, CNT. Users type those: they are the same addresses, and are
// printed back the short way.
TEST(Address, CxProgrammerNamesOf5_2_2AreasAreAliases) {
    const Form aliases[] = {
        {"DM100", "D100", {Area::dm, 0, 100, std::nullopt}},
        {"dm100.3", "D100.03", {Area::dm, 0, 100, 3}},
        {"HR0", "H0", {Area::holding, 0, 0, std::nullopt}},
        {"WR0", "W0", {Area::work, 0, 0, std::nullopt}},
        {"AR448", "A448", {Area::auxiliary, 0, 448, std::nullopt}},
        {"TIM5", "T5", {Area::timer, 0, 5, std::nullopt}},
        {"CNT5", "C5", {Area::counter, 0, 5, std::nullopt}},
        {"cnt4095", "C4095", {Area::counter, 0, 4095, std::nullopt}},
    };
    for (const auto& f : aliases) {
        SCOPED_TRACE(std::string(f.text));
        auto a = parse_address(f.text);
        ASSERT_TRUE(a) << a.error().message();
        EXPECT_EQ(*a, f.address);
        EXPECT_EQ(format_address(*a), f.canonical);
    }
    EXPECT_EQ(area_names(), "CIO IR DR TK W H A T C D E (also TIM CNT DM HR WR AR)");
    // The short names still win where they are a prefix: DR is a data register, not D.
    EXPECT_EQ(parse_address("DR3")->area, Area::data_register);
    EXPECT_EQ(parse_address("CIO5")->area, Area::cio);
    EXPECT_EQ(parse_address("TK2")->area, Area::task_flag);
}

TEST(Address, GoldenExamplesFromTheManual) {
    const auto v = test::load_vector("address_examples.txt");
    ASSERT_FALSE(v.source.empty());
    ASSERT_EQ(v.lines.size(), 12u);
    for (const auto& line : v.lines) {
        SCOPED_TRACE(line);
        std::istringstream in(line);
        std::string text, access_name, rest;
        in >> text >> access_name;
        std::getline(in, rest);
        const auto bytes = test::hex(rest);
        ASSERT_EQ(bytes.size(), 4u);
        Access access = Access::natural;
        if (access_name == "word") access = Access::word;
        if (access_name == "bit") access = Access::bit;
        if (access_name == "forced") access = Access::forced;
        auto a = parse_address(text);
        ASSERT_TRUE(a);
        auto m = to_memory_address(*a, access);
        ASSERT_TRUE(m) << m.error().message();
        EXPECT_EQ(*m, (MemoryAddress{bytes[0], static_cast<std::uint16_t>(bytes[1] << 8 | bytes[2]),
                                     bytes[3]}));
    }
}

MemoryAddress mem(std::string_view text, Access access = Access::natural) {
    auto a = parse_address(text);
    EXPECT_TRUE(a) << text;
    auto m = to_memory_address(a.value_or(Address{}), access);
    EXPECT_TRUE(m) << text << ": " << (m ? "" : m.error().message());
    return m.value_or(MemoryAddress{0xFF, 0xFFFF, 0xFF});
}

TEST(Address, ToMemoryAddress) {
    EXPECT_EQ(mem("D100"), (MemoryAddress{0x82, 100, 0}));
    EXPECT_EQ(mem("D100.15"), (MemoryAddress{0x02, 100, 15}));
    EXPECT_EQ(mem("W5"), (MemoryAddress{0xB1, 5, 0}));
    EXPECT_EQ(mem("H10.1"), (MemoryAddress{0x32, 10, 1}));
    EXPECT_EQ(mem("A448"), (MemoryAddress{0xB3, 448, 0}));
    EXPECT_EQ(mem("A448.3"), (MemoryAddress{0x33, 448, 3}));
    // T/C: the word is the PV (89), counters 0x8000 higher; bit access = completion flag.
    EXPECT_EQ(mem("T10"), (MemoryAddress{0x89, 10, 0}));
    EXPECT_EQ(mem("C10"), (MemoryAddress{0x89, 0x800A, 0}));
    EXPECT_EQ(mem("T10", Access::bit), (MemoryAddress{0x09, 10, 0}));
    EXPECT_EQ(mem("C10", Access::bit), (MemoryAddress{0x09, 0x800A, 0}));
    EXPECT_EQ(mem("C10", Access::forced), (MemoryAddress{0x49, 0x800A, 0}));
    EXPECT_EQ(mem("T10", Access::word), (MemoryAddress{0x89, 10, 0}));
    // Forced status.
    EXPECT_EQ(mem("W5.2", Access::forced), (MemoryAddress{0x71, 5, 2}));
    EXPECT_EQ(mem("H7", Access::forced), (MemoryAddress{0xF2, 7, 0}));
    // EM banks: 0-F -> A0+n / 20+n, 10-18 -> 60+(n-16) / E0+(n-16).
    EXPECT_EQ(mem("E3_100"), (MemoryAddress{0xA3, 100, 0}));
    EXPECT_EQ(mem("EF_1"), (MemoryAddress{0xAF, 1, 0}));
    EXPECT_EQ(mem("E10_5"), (MemoryAddress{0x60, 5, 0}));
    EXPECT_EQ(mem("E18_5"), (MemoryAddress{0x68, 5, 0}));
    EXPECT_EQ(mem("E0_0.5"), (MemoryAddress{0x20, 0, 5}));
    EXPECT_EQ(mem("E18_1.2"), (MemoryAddress{0xE8, 1, 2}));
    EXPECT_EQ(mem("E100"), (MemoryAddress{0x98, 100, 0}));
    EXPECT_EQ(mem("E100.4"), (MemoryAddress{0x0A, 100, 4}));
    // Registers and task flags.
    EXPECT_EQ(mem("IR0"), (MemoryAddress{0xDC, 0x0100, 0}));
    EXPECT_EQ(mem("IR15"), (MemoryAddress{0xDC, 0x010F, 0}));
    EXPECT_EQ(mem("DR3"), (MemoryAddress{0xBC, 0x0203, 0}));
    EXPECT_EQ(mem("TK2"), (MemoryAddress{0x06, 2, 0}));
    EXPECT_EQ(mem("TK2", Access::bit), (MemoryAddress{0x06, 2, 0}));
    EXPECT_EQ(mem("10.13"), (MemoryAddress{0x30, 10, 13}));
    // Every result names a row of the 5-2-2 table.
    for (const auto& f : forms) {
        const auto m = mem(f.text);
        EXPECT_NE(find_segment(m.area_code, m.word), nullptr) << f.text;
    }
}

// Choices where 5-2-2 has no code: each maps to a specific AddressError.
TEST(Address, ToMemoryAddressRefusals) {
    auto err = [](std::string_view text, Access access) {
        auto a = parse_address(text);
        EXPECT_TRUE(a) << text;
        auto m = to_memory_address(a.value_or(Address{}), access);
        EXPECT_FALSE(m) << text;
        return m ? std::error_code{} : m.error();
    };
    EXPECT_EQ(err("D100", Access::forced), AddressError::unknown_area);
    EXPECT_EQ(err("A448", Access::forced), AddressError::unknown_area);
    EXPECT_EQ(err("E3_1", Access::forced), AddressError::unknown_area);
    EXPECT_EQ(err("IR0", Access::bit), AddressError::bit_not_allowed);
    EXPECT_EQ(err("DR0", Access::forced), AddressError::unknown_area);
    EXPECT_EQ(err("TK2", Access::word), AddressError::bit_required);
    EXPECT_EQ(err("TK2", Access::forced), AddressError::unknown_area);
    EXPECT_EQ(err("D100.1", Access::word), AddressError::bit_not_allowed);
    EXPECT_EQ(err("D100", Access::bit), AddressError::bit_required);
    // Hand-built addresses are range-checked too.
    EXPECT_EQ(to_memory_address(Address{Area::em, 0x19, 0, std::nullopt}).error(),
              AddressError::bank_out_of_range);
    EXPECT_EQ(to_memory_address(Address{Area::work, 0, 512, std::nullopt}).error(),
              AddressError::word_out_of_range);
    EXPECT_EQ(to_memory_address(Address{Area::dm, 0, 0, 16}).error(),
              AddressError::bit_out_of_range);
    EXPECT_EQ(to_memory_address(Address{Area::timer, 0, 0, 1}).error(),
              AddressError::bit_not_allowed);
}

TEST(Address, MaxWord) {
    EXPECT_EQ(max_word(Area::cio), 6143);
    EXPECT_EQ(max_word(Area::work), 511);
    EXPECT_EQ(max_word(Area::holding), 511);
    EXPECT_EQ(max_word(Area::auxiliary), 959);
    EXPECT_EQ(max_word(Area::timer), 4095);
    EXPECT_EQ(max_word(Area::counter), 4095);
    EXPECT_EQ(max_word(Area::dm), 32767);
    EXPECT_EQ(max_word(Area::em), 32767);
    EXPECT_EQ(max_word(Area::em_current), 32767);
    EXPECT_EQ(max_word(Area::index_register), 15);
    EXPECT_EQ(max_word(Area::data_register), 15);
    EXPECT_EQ(max_word(Area::task_flag), 31);
}

}  // namespace
}  // namespace fins
