// 22 20 MEMORY CASSETTE TRANSFER through full request frames (W342 5-3-43, the 5-1-2
// row and notes): the CP1H profile's Memory Cassette saves, loads, verifies, initializes
// and reports its data types; the choices of server/handlers/memory_cassette.cpp.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "fins/commands/memory_cassette.hpp"
#include "fins/commands/parameter_area.hpp"
#include "server/handlers/file_support.hpp"

namespace fins::test {
namespace {

using plc::OperatingMode;

plc::Profile cp1h() {
    return *plc::find_profile("cp1h");
}

MemoryCassetteTransfer cassette(CassetteOperation op, std::uint16_t designation = 0) {
    return {disk_memory_cassette, static_cast<std::uint16_t>(op), designation};
}

std::uint16_t stored_type(Harness& h) {
    const auto r = run(h, cassette(CassetteOperation::read_type));
    EXPECT_EQ(r.end_code(), 0x0000);
    const auto d = r.data();
    return d.size() == 2 ? static_cast<std::uint16_t>(d[0] << 8 | d[1]) : 0xFFFF;
}

struct Cp1h : Harness {
    Cp1h() : Harness(cp1h()) { plc.set_mode(OperatingMode::program); }
    std::span<std::uint16_t> dm() { return memory().words(Region::dm); }
    std::span<std::uint16_t> setup() { return plc.parameters().words(parameter_area_plc_setup); }
    std::span<std::uint8_t> um() { return plc.program().bytes(); }
};

// All areas (bit 15 OFF): program, parameters and DM go to the cassette and back; the
// stored data type names every item (bits 07-02 and 00; 01 FB sources: finsd has none).
TEST(MemoryCassette, W342_5_3_43_SaveVerifyLoadAllAreas) {
    Cp1h h;
    EXPECT_EQ(stored_type(h), 0x0000);
    h.dm()[0] = 0x1234;
    h.dm()[32767] = 0xBEEF;
    h.setup()[3] = 0x00AA;
    h.um()[5] = 0x42;
    ASSERT_EQ(run(h, cassette(CassetteOperation::save)).end_code(), 0x0000);
    EXPECT_EQ(stored_type(h), 0x00FD);
    EXPECT_EQ(run(h, cassette(CassetteOperation::verify)).end_code(), 0x0000);
    // A difference in any area: 2007, nothing in the response.
    h.dm()[32767] = 0;
    const auto r = run(h, cassette(CassetteOperation::verify));
    EXPECT_EQ(r.end_code(), 0x2007);
    EXPECT_TRUE(r.data().empty());
    h.setup()[3] = 0;
    h.um()[5] = 0;
    h.dm()[0] = 0;
    ASSERT_EQ(run(h, cassette(CassetteOperation::load)).end_code(), 0x0000);
    EXPECT_EQ(h.dm()[0], 0x1234);
    EXPECT_EQ(h.dm()[32767], 0xBEEF);
    EXPECT_EQ(h.setup()[3], 0x00AA);
    EXPECT_EQ(h.um()[5], 0x42);
    EXPECT_EQ(run(h, cassette(CassetteOperation::verify)).end_code(), 0x0000);
}

// Bit 15 ON: only the areas named. A save keeps the other items; a load of an area the
// cassette does not hold answers 2006 and loads nothing; "all" loads what it holds.
TEST(MemoryCassette, W342_5_3_43_IndividualAreas) {
    Cp1h h;
    h.dm()[10] = 0x0A0A;
    ASSERT_EQ(
        run(h, cassette(CassetteOperation::save, cassette_individual | cassette_dm)).end_code(),
        0x0000);
    EXPECT_EQ(stored_type(h), cassette_dm);
    h.um()[0] = 0x11;
    ASSERT_EQ(run(h, cassette(CassetteOperation::save, cassette_individual | cassette_program))
                  .end_code(),
              0x0000);
    EXPECT_EQ(stored_type(h), cassette_dm | cassette_program);
    h.dm()[10] = 0;
    h.um()[0] = 0x22;
    EXPECT_EQ(run(h, cassette(CassetteOperation::load,
                              cassette_individual | cassette_dm | cassette_parameters))
                  .end_code(),
              0x2006);
    EXPECT_EQ(h.dm()[10], 0);
    EXPECT_EQ(run(h, cassette(CassetteOperation::verify, cassette_individual | cassette_comments))
                  .end_code(),
              0x2006);
    ASSERT_EQ(
        run(h, cassette(CassetteOperation::load, cassette_individual | cassette_dm)).end_code(),
        0x0000);
    EXPECT_EQ(h.dm()[10], 0x0A0A);
    EXPECT_EQ(h.um()[0], 0x22);
    ASSERT_EQ(run(h, cassette(CassetteOperation::load)).end_code(), 0x0000);
    EXPECT_EQ(h.um()[0], 0x11);
    // Areas finsd does not have (comments ...) are empty: saved, reported, always equal.
    ASSERT_EQ(run(h, cassette(CassetteOperation::save, cassette_individual | cassette_comments))
                  .end_code(),
              0x0000);
    EXPECT_EQ(stored_type(h), cassette_dm | cassette_program | cassette_comments);
    EXPECT_EQ(run(h, cassette(CassetteOperation::verify, cassette_individual | cassette_comments))
                  .end_code(),
              0x0000);
}

// 0003 erases the cassette; then there is nothing to load or verify (2006).
TEST(MemoryCassette, W342_5_3_43_Initialize) {
    Cp1h h;
    ASSERT_EQ(run(h, cassette(CassetteOperation::save)).end_code(), 0x0000);
    ASSERT_EQ(run(h, cassette(CassetteOperation::initialize)).end_code(), 0x0000);
    EXPECT_EQ(stored_type(h), 0x0000);
    EXPECT_EQ(run(h, cassette(CassetteOperation::load)).end_code(), 0x2006);
    EXPECT_EQ(run(h, cassette(CassetteOperation::verify)).end_code(), 0x2006);
}

// 110C: only disk 8003; parameters 0000-0003 and 8000; the designation note (bit 15 OFF
// with area bits ON), bit 15 ON with no area, reserved bits 14-08 and 01.
TEST(MemoryCassette, W342_5_3_43_ParameterErrors110C) {
    Cp1h h;
    EXPECT_EQ(run(h, MemoryCassetteTransfer{disk_memory_card, 0, 0}).end_code(), 0x110C);
    EXPECT_EQ(run(h, MemoryCassetteTransfer{disk_memory_cassette, 0x0004, 0}).end_code(), 0x110C);
    EXPECT_EQ(run(h, cassette(CassetteOperation::save, cassette_dm)).end_code(), 0x110C);
    EXPECT_EQ(run(h, cassette(CassetteOperation::load, cassette_program)).end_code(), 0x110C);
    EXPECT_EQ(run(h, cassette(CassetteOperation::save, cassette_individual)).end_code(), 0x110C);
    EXPECT_EQ(run(h, cassette(CassetteOperation::save, 0x8002)).end_code(), 0x110C);
    EXPECT_EQ(run(h, cassette(CassetteOperation::verify, 0x8140)).end_code(), 0x110C);
    EXPECT_EQ(stored_type(h), 0x0000);  // nothing was written
    // 0003 and 8000 ignore the designation.
    EXPECT_EQ(run(h, cassette(CassetteOperation::initialize, 0x7F02)).end_code(), 0x0000);
    EXPECT_EQ(run(h, cassette(CassetteOperation::read_type, 0x7F02)).end_code(), 0x0000);
    // Frame lengths: 1002 / 1001.
    EXPECT_EQ(h.send("2220 8003 0000 00").end_code(), 0x1002);
    EXPECT_EQ(h.send("2220 8003 0000 0000 00").end_code(), 0x1001);
}

// 5-1-2 row: PROGRAM mode only (2206 RUN, 2205 MONITOR); no cassette: 2301.
TEST(MemoryCassette, W342_5_3_43_ProgramModeOnlyAndMissingCassette) {
    Cp1h h;
    h.plc.set_mode(OperatingMode::run);
    EXPECT_EQ(run(h, cassette(CassetteOperation::read_type)).end_code(), 0x2206);
    h.plc.set_mode(OperatingMode::monitor);
    EXPECT_EQ(run(h, cassette(CassetteOperation::save)).end_code(), 0x2205);
    h.plc.set_mode(OperatingMode::program);
    h.plc.files().mount_cassette(false);
    for (const auto op :
         {CassetteOperation::save, CassetteOperation::load, CassetteOperation::verify,
          CassetteOperation::initialize, CassetteOperation::read_type})
        EXPECT_EQ(run(h, cassette(op)).end_code(), 0x2301);
    h.plc.files().mount_cassette(true);
    EXPECT_EQ(run(h, cassette(CassetteOperation::read_type)).end_code(), 0x0000);
}

// 5-3-43 note (CPU -> cassette) and 5-1-2 note 4 (cassette -> program area): with DIP
// switch UM write protection nothing that includes the user program moves (2101).
TEST(MemoryCassette, W342_5_3_43_DipProtectionBlocksTheProgram) {
    Cp1h h;
    ASSERT_EQ(run(h, cassette(CassetteOperation::save)).end_code(), 0x0000);
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(run(h, cassette(CassetteOperation::save)).end_code(), 0x2101);
    EXPECT_EQ(run(h, cassette(CassetteOperation::save, cassette_individual | cassette_program))
                  .end_code(),
              0x2101);
    EXPECT_EQ(run(h, cassette(CassetteOperation::load)).end_code(), 0x2101);
    EXPECT_EQ(
        run(h, cassette(CassetteOperation::save, cassette_individual | cassette_dm)).end_code(),
        0x0000);
    EXPECT_EQ(
        run(h, cassette(CassetteOperation::load, cassette_individual | cassette_dm)).end_code(),
        0x0000);
    EXPECT_EQ(run(h, cassette(CassetteOperation::verify)).end_code(), 0x0000);
}

// Only the CP1H has a Memory Cassette: every other profile answers 0401 (5-1-1 "CP1H
// CPU Units, CP1L CPU Units only"), in any mode.
TEST(MemoryCassette, W342_5_3_43_UndefinedWithoutACassette) {
    for (const auto& profile : plc::profiles()) {
        Harness h(profile);
        h.plc.set_mode(OperatingMode::program);
        EXPECT_EQ(run(h, cassette(CassetteOperation::read_type)).end_code(),
                  profile.name == "cp1h" ? 0x0000 : 0x0401)
            << profile.name;
    }
}

// The items live under the data directory (<root>/cassette/AUTOEXEC.xxx, the data file
// formats: 48 header bytes, then the data); an item edited to a wrong size answers 250F
// and loads nothing.
TEST(MemoryCassette, W342_5_3_43_ItemsUnderTheDataDirectory) {
    namespace fs = std::filesystem;
    std::string pattern = (fs::temp_directory_path() / "fins-cassette-test-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    const fs::path root = pattern;
    {
        Cp1h h;
        ASSERT_TRUE(h.plc.files().attach(root));
        h.dm()[0] = 0x1234;
        ASSERT_EQ(run(h, cassette(CassetteOperation::save)).end_code(), 0x0000);
        EXPECT_EQ(fs::file_size(root / "cassette" / "AUTOEXEC.IOM"), 48U + 32768U * 2);
        EXPECT_EQ(fs::file_size(root / "cassette" / "AUTOEXEC.STD"), 16048U);
        EXPECT_EQ(fs::file_size(root / "cassette" / "AUTOEXEC.CMT"), 48U);
        {
            std::ifstream in(root / "cassette" / "AUTOEXEC.IOM", std::ios::binary);
            in.seekg(48);
            EXPECT_EQ(in.get(), 0x12);
            EXPECT_EQ(in.get(), 0x34);
        }
        fs::resize_file(root / "cassette" / "AUTOEXEC.IOM", 100);
        h.dm()[0] = 0;
        EXPECT_EQ(run(h, cassette(CassetteOperation::load)).end_code(), 0x250F);
        EXPECT_EQ(h.dm()[0], 0);
    }
    {
        // A new finsd on the same data directory finds the cassette as it was left.
        Cp1h h;
        ASSERT_TRUE(h.plc.files().attach(root));
        EXPECT_EQ(stored_type(h), 0x00FD);
    }
    fs::remove_all(root);
}

}  // namespace
}  // namespace fins::test
