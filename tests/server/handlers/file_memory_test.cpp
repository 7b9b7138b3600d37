// 22 01 .. 22 08, 22 15 through full request frames (W342 5-3-32 .. 5-3-38, 5-3-42):
// responses laid out as the seed gives them, every end code the model answers, the
// execution conditions of 5-1-2 and the FINS write access log.
#include <gtest/gtest.h>

#include <string>

#include <fmt/core.h>

#include "fins/commands/file_memory.hpp"
#include "server/frame_builder.hpp"
#include "server/handlers/file_support.hpp"

namespace fins::test {
namespace {

TEST(FileMemoryHandlers, W342_5_3_34_WriteThenRead_5_3_33) {
    Harness h;
    const auto content = text_bytes("hello, card");
    EXPECT_EQ(
        run(h, SingleFileWrite{disk_memory_card, 0, file("HELLO.TXT"), 0, content, ""}).end_code(),
        0x0000);
    const auto r = run(h, SingleFileRead{disk_memory_card, file("hello.txt"), 7, 100, ""});
    ASSERT_EQ(r.end_code(), 0x0000);
    // File capacity 11, position 7, 4 bytes with bit 15 (last byte included), data.
    EXPECT_EQ(r.data_hex(), "00 00 00 0B 00 00 00 07 80 04 63 61 72 64");
    // Position 0, length 0: the existence check of 5-3-33.
    const auto check = run(h, SingleFileRead{disk_memory_card, file("HELLO.TXT"), 0, 0, ""});
    ASSERT_EQ(check.end_code(), 0x0000);
    EXPECT_EQ(check.data_hex(), "00 00 00 0B 00 00 00 00 00 00");
    EXPECT_EQ(run(h, SingleFileRead{disk_memory_card, file("NONE.TXT"), 0, 0, ""}).end_code(),
              0x2006);
    EXPECT_EQ(run(h, SingleFileRead{disk_memory_card, file("HELLO.TXT"), 12, 1, ""}).end_code(),
              0x1103);
    EXPECT_EQ(run(h, SingleFileRead{disk_memory_card, file("HELLO.TXT"), 0, 1989, ""}).end_code(),
              0x110C);
    EXPECT_EQ(
        run(h, SingleFileWrite{disk_memory_card, 0, file("HELLO.TXT"), 0, content, ""}).end_code(),
        0x2107);
}

TEST(FileMemoryHandlers, W342_5_3_32_DiskDataAndEntries) {
    Harness h;
    const auto content = text_bytes("12345");
    ASSERT_EQ(
        run(h, SingleFileWrite{disk_memory_card, 0, file("A.IOM"), 0, content, ""}).end_code(),
        0x0000);
    ASSERT_EQ(run(h, DirectoryCreateDelete{disk_memory_card, 0, file("LOGS"), ""}).end_code(),
              0x0000);
    const auto r = run(h, FileNameRead{disk_memory_card, 0, 20, ""});
    ASSERT_EQ(r.end_code(), 0x0000);
    const auto d = r.data();
    // 5-3-32: the root's volume label is counted and listed as a file (attribute 08).
    ASSERT_EQ(d.size(), 28U + 3 * 22);
    EXPECT_EQ(to_hex(Bytes(d).first(12)), to_hex(file("MEMCARD").bytes));
    EXPECT_EQ(to_hex(Bytes(d).subspan(16, 4)), "01 E0 00 00");  // 30,720 KB
    EXPECT_EQ(to_hex(Bytes(d).subspan(20, 4)), "01 DF FF FB");  // minus 5 bytes
    EXPECT_EQ(to_hex(Bytes(d).subspan(24, 4)), "00 03 80 03");  // 3 files, 3 + last
    EXPECT_EQ(to_hex(Bytes(d).subspan(28, 12)), to_hex(file("MEMCARD").bytes));
    EXPECT_EQ(to_hex(Bytes(d).subspan(40, 4)), to_hex(Bytes(d).subspan(12, 4)));  // its date
    EXPECT_EQ(to_hex(Bytes(d).subspan(44, 6)), "00 00 00 00 00 08");  // size 0, volume label
    EXPECT_EQ(to_hex(Bytes(d).subspan(50, 12)), to_hex(file("A.IOM").bytes));
    EXPECT_EQ(to_hex(Bytes(d).subspan(66, 6)), "00 00 00 05 00 20");  // size, archive
    EXPECT_EQ(to_hex(Bytes(d).subspan(72, 12)), to_hex(file("LOGS").bytes));
    EXPECT_EQ(to_hex(Bytes(d).subspan(92, 2)), "00 10");  // sub-directory
    // Disk data only.
    const auto disk = run(h, FileNameRead{disk_memory_card, 0, 0, ""});
    ASSERT_EQ(disk.end_code(), 0x0000);
    EXPECT_EQ(disk.data().size(), 28U);
    EXPECT_EQ(run(h, FileNameRead{disk_memory_card, 0, 21, ""}).end_code(), 0x110C);
    EXPECT_EQ(run(h, FileNameRead{disk_memory_card, 0, 1, "\\NONE"}).end_code(), 0x2006);
    EXPECT_EQ(run(h, FileNameRead{disk_memory_card, 0, 1, "\\.."}).end_code(), 0x110C);
    EXPECT_EQ(run(h, FileNameRead{disk_em_file, 0, 1, ""}).end_code(), 0x2301);
    EXPECT_EQ(run(h, FileNameRead{0x0001, 0, 1, ""}).end_code(), 0x110C);
    EXPECT_EQ(h.send("2201 8000 0000 0001 0005 5C").end_code(), 0x1002);
    EXPECT_EQ(h.send("2201 8000 0000 0001 0000 00").end_code(), 0x1001);
}

TEST(FileMemoryHandlers, W342_5_3_36_DeleteSeveralIgnoringMissing) {
    Harness h;
    const auto content = text_bytes("x");
    for (const char* n : {"A", "B", "C"})
        ASSERT_EQ(run(h, SingleFileWrite{disk_memory_card, 0, file(n), 0, content, ""}).end_code(),
                  0x0000);
    const auto r = run(h, FileDelete{disk_memory_card, {file("A"), file("NOPE"), file("C")}, ""});
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 02");
    // A bad name anywhere in the list: 110C and nothing deleted.
    FileName bad = file("B");
    bad.bytes[0] = 0xE5;
    EXPECT_EQ(run(h, FileDelete{disk_memory_card, {file("B"), bad}, ""}).end_code(), 0x110C);
    EXPECT_EQ(run(h, SingleFileRead{disk_memory_card, file("B"), 0, 0, ""}).end_code(), 0x0000);
    EXPECT_EQ(run(h, FileDelete{disk_memory_card, {file("B")}, "\\NONE"}).end_code(), 0x2106);
}

TEST(FileMemoryHandlers, W342_5_3_37_CopyBetweenDevices) {
    plc::Profile p = plc::cj2h();
    p.em_file_bank = 0x10;
    Harness h(p);
    const auto content = text_bytes("copy me");
    ASSERT_EQ(
        run(h, SingleFileWrite{disk_memory_card, 0, file("A.TXT"), 0, content, ""}).end_code(),
        0x0000);
    EXPECT_EQ(run(h, FileCopy{disk_memory_card, file("A.TXT"), disk_em_file, file("B.TXT"), "", ""})
                  .end_code(),
              0x0000);
    const auto r = run(h, SingleFileRead{disk_em_file, file("B.TXT"), 0, 100, ""});
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data().size(), 10U + 7);
    // Destination exists: 2107; source missing: 2006; destination directory missing: 2106.
    EXPECT_EQ(run(h, FileCopy{disk_memory_card, file("A.TXT"), disk_em_file, file("B.TXT"), "", ""})
                  .end_code(),
              0x2107);
    EXPECT_EQ(run(h, FileCopy{disk_memory_card, file("N.TXT"), disk_em_file, file("C.TXT"), "", ""})
                  .end_code(),
              0x2006);
    EXPECT_EQ(
        run(h, FileCopy{disk_memory_card, file("A.TXT"), disk_em_file, file("C.TXT"), "", "\\NONE"})
            .end_code(),
        0x2106);
    // 5-3-37: the copy keeps the source's date.
    const auto src = run(h, FileNameRead{disk_memory_card, 0, 1, ""}).data();
    const auto dst = run(h, FileNameRead{disk_em_file, 0, 1, ""}).data();
    EXPECT_EQ(to_hex(Bytes(src).subspan(40, 4)), to_hex(Bytes(dst).subspan(40, 4)));
}

TEST(FileMemoryHandlers, W342_5_3_38_RenameFilesAndDirectories) {
    Harness h;
    const auto content = text_bytes("x");
    ASSERT_EQ(run(h, SingleFileWrite{disk_memory_card, 0, file("A"), 0, content, ""}).end_code(),
              0x0000);
    ASSERT_EQ(run(h, SingleFileWrite{disk_memory_card, 0, file("B"), 0, content, ""}).end_code(),
              0x0000);
    ASSERT_EQ(run(h, DirectoryCreateDelete{disk_memory_card, 0, file("D"), ""}).end_code(), 0x0000);
    EXPECT_EQ(run(h, FileNameChange{disk_memory_card, file("A"), file("B"), ""}).end_code(),
              0x2107);
    EXPECT_EQ(run(h, FileNameChange{disk_memory_card, file("A"), file("C"), ""}).end_code(),
              0x0000);
    EXPECT_EQ(run(h, FileNameChange{disk_memory_card, file("A"), file("E"), ""}).end_code(),
              0x2106);
    EXPECT_EQ(run(h, FileNameChange{disk_memory_card, file("D"), file("DIR"), ""}).end_code(),
              0x0000);
    EXPECT_EQ(run(h, FileNameRead{disk_memory_card, 0, 1, "\\DIR"}).end_code(), 0x0000);
}

TEST(FileMemoryHandlers, W342_5_3_35_FormatClearsTheCard) {
    Harness h;
    const auto content = text_bytes("x");
    ASSERT_EQ(run(h, SingleFileWrite{disk_memory_card, 0, file("A"), 0, content, ""}).end_code(),
              0x0000);
    EXPECT_EQ(run(h, FileMemoryFormat{disk_memory_card}).end_code(), 0x0000);
    EXPECT_EQ(run(h, SingleFileRead{disk_memory_card, file("A"), 0, 0, ""}).end_code(), 0x2006);
    EXPECT_EQ(run(h, FileMemoryFormat{disk_em_file}).end_code(), 0x2301);
    h.plc.files().remove_card();
    EXPECT_EQ(run(h, FileMemoryFormat{disk_memory_card}).end_code(), 0x2301);
}

// 5-1-2: the 22 xx writes need the access right and obey network write protection;
// each lands in the FINS write access log (5-3-30). Reads run under both.
TEST(FileMemoryHandlers, W342_5_1_2_ConditionsAndWriteAccessLog) {
    Harness h;
    const auto content = text_bytes("x");
    const SingleFileWrite write{disk_memory_card, 0, file("A"), 0, content, ""};
    h.plc.set_network_write_protection(true);
    EXPECT_EQ(run(h, write).end_code(), 0x2102);
    EXPECT_EQ(run(h, FileNameRead{disk_memory_card, 0, 1, ""}).end_code(), 0x0000);
    h.plc.set_network_write_protection(false);
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(run(h, write).end_code(), 0x3001);
    EXPECT_EQ(run(h, DirectoryCreateDelete{disk_memory_card, 0, file("D"), ""}).end_code(), 0x3001);
    h.plc.set_access_right_holder(std::nullopt);
    h.plc.write_access_log().clear();
    EXPECT_EQ(run(h, write).end_code(), 0x0000);
    ASSERT_EQ(h.plc.write_access_log().size(), 1U);
    EXPECT_EQ(h.plc.write_access_log().at(0).command, (CommandCode{0x22, 0x03}));
}

// 05 01 reports the card as inserted now and the banks before the EM file banks.
TEST(FileMemoryHandlers, W342_5_3_15_CpuUnitDataFollowsTheCardAndEmFileBanks) {
    plc::Profile p = plc::cj2h();
    p.em_file_bank = 0x10;
    Harness h(p);
    auto d = h.send("0501").data();
    ASSERT_GE(d.size(), 92U);
    EXPECT_EQ(d[86], 0x10);                                  // non-file EM banks
    EXPECT_EQ(to_hex(Bytes(d).subspan(89, 3)), "04 78 00");  // 30,720 KB
    h.plc.files().remove_card();
    d = h.send("0501").data();
    EXPECT_EQ(to_hex(Bytes(d).subspan(89, 3)), "00 00 00");
    h.plc.files().insert_card(0x800);
    d = h.send("0501").data();
    EXPECT_EQ(to_hex(Bytes(d).subspan(89, 3)), "04 08 00");
}

}  // namespace
}  // namespace fins::test
