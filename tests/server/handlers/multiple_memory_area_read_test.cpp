// 01 04 MULTIPLE MEMORY AREA READ through full request frames (W342 5-3-5).
#include <gtest/gtest.h>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

TEST(MultipleMemoryAreaRead, W342_5_3_5_EachElementEchoesItsAreaCode) {
    Harness h;
    auto& m = h.memory();
    m.words(Region::dm)[10] = 0x1234;
    m.words(Region::cio)[10] = 0x2000;
    m.index_registers()[0] = 0xCAFEF00D;
    m.set_completion_flag(plc::counter_base + 2, true);
    const auto reply = h.send("0104 82000A00 30000A0D DC010000 09800200 07100F00 BC0F0000");
    EXPECT_EQ(reply.end_code(), 0x0000);
    EXPECT_EQ(reply.data_hex(), to_hex(hex("82 1234 30 01 DC CAFEF00D 09 01 07 01 BC 0000")));
}

TEST(MultipleMemoryAreaRead, W342_5_3_5_ForcedStatusCodesAreListed) {
    Harness h;
    auto& m = h.memory();
    ASSERT_TRUE(m.force_bit(Region::work, 1, 2, true));
    ASSERT_TRUE(m.force_completion_flag(5, false));
    m.words(Region::work)[1] |= 0x0001;
    const auto reply = h.send("0104 71000102 71000100 F1000100 49000500 41000500");
    EXPECT_EQ(reply.end_code(), 0x0000);
    EXPECT_EQ(reply.data_hex(), to_hex(hex("71 03 71 01 F1 0004 0005 49 02 41 02")));
}

TEST(MultipleMemoryAreaRead, W342_5_3_5_NothingAfterTheCommandCodeIsNormal) {
    Harness h;
    const auto reply = h.send("0104");
    EXPECT_EQ(reply.end_code(), 0x0000);
    EXPECT_TRUE(reply.data().empty());
}

TEST(MultipleMemoryAreaRead, W342_5_3_5_AnyBadElementReadsNothing) {
    Harness h;
    const auto bad_code = h.send("0104 82000000 FF000000 82000100");
    EXPECT_EQ(bad_code.end_code(), 0x1101);
    EXPECT_TRUE(bad_code.data().empty());
    EXPECT_EQ(h.send("0104 82000000 82800000").end_code(), 0x1103);
    EXPECT_EQ(h.send("0104 82000000 30000010").end_code(), 0x1103);
    EXPECT_EQ(h.send("0104 82000001").end_code(), 0x1103);
}

TEST(MultipleMemoryAreaRead, W342_5_3_5_167ElementsIsTheLimit) {
    Harness h;
    std::string items;
    for (int i = 0; i < 167; ++i)
        items += "DC010F00";
    const auto ok = h.send("0104" + items);
    EXPECT_EQ(ok.end_code(), 0x0000);
    EXPECT_EQ(ok.data().size(), 167U * 5U);
    EXPECT_EQ(h.send("0104" + items + "82000000").end_code(), 0x1001);
}

TEST(MultipleMemoryAreaRead, W342_5_1_3_PartialElementIs1002) {
    Harness h;
    EXPECT_EQ(h.send("0104 82").end_code(), 0x1002);
    EXPECT_EQ(h.send("0104 82000000 820000").end_code(), 0x1002);
}

TEST(MultipleMemoryAreaRead, W342_5_1_3_EmBankTheModelLacksIs1101) {
    plc::Profile p = plc::cj2h();
    p.em_banks = 0;
    Harness h(p);
    EXPECT_EQ(h.send("0104 A0000000").end_code(), 0x1101);
    EXPECT_EQ(h.send("0104 98000000").end_code(), 0x1101);
    EXPECT_EQ(h.send("0104 82000000").end_code(), 0x0000);
}

}  // namespace
}  // namespace fins::test
