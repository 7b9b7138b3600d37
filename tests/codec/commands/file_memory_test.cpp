// Commands 22 01 .. 22 15 (W342 5-3-32 .. 5-3-42; layouts fins-frames 6 "22 xx" and
// frames-serial-files 4): encode -> decode -> compare, every shorter prefix fails with
// 1002, one byte more with 1001; response decoding refuses wrong lengths and echoes.
#include <gtest/gtest.h>

#include <algorithm>

#include "codec/test_support.hpp"
#include "fins/commands/file_memory.hpp"

namespace fins {
namespace {

using test::encode;
using test::expect_longer_fails;
using test::expect_shorter_prefixes_fail;
using test::hex;
using test::prefix;

FileName name(std::string_view text) {
    return *FileName::from(text);
}

std::vector<std::uint8_t> bytes_of(const FileName& n) {
    return {n.bytes.begin(), n.bytes.end()};
}

// "Volume Labels and File Names": 8 + "." + 3, padded with 20 hex; no extension: "."
// and the extension are 20 hex too.
TEST(FileName, W342_5_1_NameLayout) {
    EXPECT_EQ(bytes_of(name("AUTOEXEC.IOM")), hex("4155544F45584543 2E 494F4D"));
    EXPECT_EQ(bytes_of(name("A.B")), hex("41202020202020202E422020"));
    EXPECT_EQ(bytes_of(name("DATA")), hex("444154412020202020202020"));
    EXPECT_EQ(name("A.B").text(), "A.B");
    EXPECT_EQ(name("DATA").text(), "DATA");
    EXPECT_FALSE(FileName::from("TOOLONGNAME.X"));
    EXPECT_FALSE(FileName::from("A.LONG"));
    EXPECT_FALSE(FileName::from(".IOM"));
    EXPECT_FALSE(FileName::from("A.B.C"));
}

// 5-3-32 note: bits 31-25 year-1980 ... 4-0 second/2.
TEST(FileName, W342_5_3_32_DatePacking) {
    EXPECT_EQ(pack_file_date(2024, 5, 17, 13, 45, 30), 0x58B16DAFu);
    EXPECT_EQ(pack_file_date(1980, 1, 1, 0, 0, 0), 0x00210000u);
}

TEST(FileNameRead, W342_5_3_32_RoundTrip) {
    const FileNameRead c{disk_memory_card, 0, 20, "\\LOGS"};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8000 0000 0014 0005 5C4C4F4753"));
    const auto d = FileNameRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->disk, 0x8000);
    EXPECT_EQ(d->count, 20);
    EXPECT_EQ(d->directory, "\\LOGS");
    expect_shorter_prefixes_fail<FileNameRead>(params);
    expect_longer_fails<FileNameRead>(params);
}

TEST(FileNameRead, W342_5_3_32_Response) {
    FileNameReadResponse r;
    r.disk = {name("MEMCARD"), 0x58B16DAF, 0x01E00000, 0x01DFF000, 3};
    r.last = true;
    r.files = {{name("A.IOM"), 0x58B16DAF, 100, attribute_archive},
               {name("SUB"), 0x58B16DAF, 0, attribute_directory}};
    const auto data = encode(r);
    ASSERT_EQ(data.size(), disk_data_size + 2 + 2 * file_entry_size);
    // Disk data: label, date, total, free, total files; then 8002 (2 files, last).
    EXPECT_EQ(std::vector<std::uint8_t>(data.begin() + 12, data.begin() + 28),
              hex("58B16DAF 01E00000 01DFF000 0003 8002"));
    // First entry: name, date, size, attribute (second byte: archive).
    EXPECT_EQ(std::vector<std::uint8_t>(data.begin() + 40, data.begin() + 50),
              hex("58B16DAF 00000064 0020"));
    const FileNameRead c{disk_memory_card, 0, 20, ""};
    const auto back = c.decode_response(data);
    ASSERT_TRUE(back);
    EXPECT_EQ(*back, r);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(c.decode_response(prefix(data, n))) << n;
    auto longer = data;
    longer.push_back(0);
    EXPECT_FALSE(c.decode_response(longer));
    const FileNameRead one{disk_memory_card, 0, 1, ""};
    EXPECT_FALSE(one.decode_response(data));  // more entries than asked
}

TEST(SingleFileRead, W342_5_3_33_RoundTrip) {
    const SingleFileRead c{disk_em_file, name("A.IOM"), 0x10, 0x0100, ""};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8001 41202020202020202E494F4D 00000010 0100 0000"));
    const auto d = SingleFileRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->file, c.file);
    EXPECT_EQ(d->position, 0x10u);
    EXPECT_EQ(d->length, 0x100);
    expect_shorter_prefixes_fail<SingleFileRead>(params);
    expect_longer_fails<SingleFileRead>(params);

    const SingleFileReadResponse r{20, 0x10, true, {1, 2, 3, 4}};
    const auto data = encode(r);
    EXPECT_EQ(data, hex("00000014 00000010 8004 01020304"));
    const auto back = c.decode_response(data);
    ASSERT_TRUE(back);
    EXPECT_EQ(*back, r);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(c.decode_response(prefix(data, n)));
    EXPECT_FALSE(c.decode_response(hex("00000014 00000011 8004 01020304")));  // position echo
}

TEST(SingleFileWrite, W342_5_3_34_RoundTrip) {
    const std::vector<std::uint8_t> payload{0xAA, 0xBB};
    const SingleFileWrite c{disk_memory_card, 0x0003, name("B.TXT"), 2, payload, "\\D"};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8000 0003 42202020202020202E545854 00000002 0002 AABB 0002 5C44"));
    const auto d = SingleFileWrite::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->mode, 3);
    EXPECT_EQ(std::vector<std::uint8_t>(d->data.begin(), d->data.end()), payload);
    EXPECT_EQ(d->directory, "\\D");
    expect_shorter_prefixes_fail<SingleFileWrite>(params);
    expect_longer_fails<SingleFileWrite>(params);
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_FALSE(c.decode_response(hex("00")));
}

TEST(FileMemoryFormat, W342_5_3_35_RoundTrip) {
    const auto params = encode(FileMemoryFormat{disk_em_file});
    EXPECT_EQ(params, hex("8001"));
    ASSERT_TRUE(FileMemoryFormat::decode(params));
    expect_shorter_prefixes_fail<FileMemoryFormat>(params);
    expect_longer_fails<FileMemoryFormat>(params);
}

TEST(FileDelete, W342_5_3_36_RoundTrip) {
    const FileDelete c{disk_memory_card, {name("A"), name("B.C")}, ""};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8000 0002 412020202020202020202020 42202020202020202E432020 0000"));
    const auto d = FileDelete::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->files, c.files);
    expect_shorter_prefixes_fail<FileDelete>(params);
    expect_longer_fails<FileDelete>(params);
    // A count the frame cannot hold: 1002 without reserving memory for it.
    EXPECT_EQ(FileDelete::decode(hex("8000 FFFF")).error(), EndCode::command_too_short);
    const auto r = c.decode_response(hex("0001"));
    ASSERT_TRUE(r);
    EXPECT_EQ(r->deleted, 1);
    EXPECT_FALSE(c.decode_response(hex("0003")));  // more than asked
    EXPECT_FALSE(c.decode_response(hex("00")));
}

TEST(FileCopy, W342_5_3_37_RoundTrip) {
    const FileCopy c{disk_memory_card, name("A"), disk_em_file, name("B"), "\\X", ""};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8000 412020202020202020202020 8001 422020202020202020202020 "
                          "0002 5C58 0000"));
    const auto d = FileCopy::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->destination_disk, disk_em_file);
    EXPECT_EQ(d->source_directory, "\\X");
    EXPECT_EQ(d->destination_directory, "");
    expect_shorter_prefixes_fail<FileCopy>(params);
    expect_longer_fails<FileCopy>(params);
}

TEST(FileNameChange, W342_5_3_38_RoundTrip) {
    const FileNameChange c{disk_memory_card, name("A"), name("B"), ""};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8000 412020202020202020202020 422020202020202020202020 0000"));
    ASSERT_TRUE(FileNameChange::decode(params));
    expect_shorter_prefixes_fail<FileNameChange>(params);
    expect_longer_fails<FileNameChange>(params);
}

TEST(MemoryAreaFileTransfer, W342_5_3_39_RoundTrip) {
    const MemoryAreaFileTransfer c{0x0000,           {0x82, 0x0064, 0x00}, 10,
                                   disk_memory_card, name("D.IOM"),        ""};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("0000 82006400 000A 8000 44202020202020202E494F4D 0000"));
    const auto d = MemoryAreaFileTransfer::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->start, c.start);
    EXPECT_EQ(d->count, 10);
    expect_shorter_prefixes_fail<MemoryAreaFileTransfer>(params);
    expect_longer_fails<MemoryAreaFileTransfer>(params);
    const auto r = c.decode_response(hex("000A"));
    ASSERT_TRUE(r);
    EXPECT_EQ(r->count, 10);
    EXPECT_FALSE(c.decode_response(hex("000A00")));
}

TEST(ParameterAreaFileTransfer, W342_5_3_40_RoundTrip) {
    const ParameterAreaFileTransfer c{0x0001,           0x8010,        0, 0xFFFF,
                                      disk_memory_card, name("P.STD"), ""};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("0001 8010 0000 FFFF 8000 50202020202020202E535444 0000"));
    ASSERT_TRUE(ParameterAreaFileTransfer::decode(params));
    expect_shorter_prefixes_fail<ParameterAreaFileTransfer>(params);
    expect_longer_fails<ParameterAreaFileTransfer>(params);
}

TEST(ProgramAreaFileTransfer, W342_5_3_41_RoundTrip) {
    const ProgramAreaFileTransfer c{0x0002,           0xFFFF,        0, 0xFFFFFFFF,
                                    disk_memory_card, name("P.OBJ"), ""};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("0002 FFFF 00000000 FFFFFFFF 8000 50202020202020202E4F424A 0000"));
    ASSERT_TRUE(ProgramAreaFileTransfer::decode(params));
    expect_shorter_prefixes_fail<ProgramAreaFileTransfer>(params);
    expect_longer_fails<ProgramAreaFileTransfer>(params);
    const auto r = c.decode_response(hex("00000100"));
    ASSERT_TRUE(r);
    EXPECT_EQ(r->length, 0x100u);
    EXPECT_FALSE(c.decode_response(hex("0100")));
}

TEST(DirectoryCreateDelete, W342_5_3_42_RoundTrip) {
    const DirectoryCreateDelete c{disk_memory_card, 0x0000, name("LOGS"), "\\A"};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8000 0000 4C4F47532020202020202020 0002 5C41"));
    const auto d = DirectoryCreateDelete::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->parent, "\\A");
    expect_shorter_prefixes_fail<DirectoryCreateDelete>(params);
    expect_longer_fails<DirectoryCreateDelete>(params);
}

}  // namespace
}  // namespace fins
