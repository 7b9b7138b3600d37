// 02 40 READ MULTIPLE ITEMS FROM FUNCTION BLOCK (seed 001): every response code of the
// seed, on the handler directly and, once the command table lists 02 40, through full
// frames. The registered blocks and ITEM values are those of plc/loop_control.hpp.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "fins/command_table.hpp"
#include "fins/commands/loop_control.hpp"
#include "server/frame_builder.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::test {
namespace {

plc::Profile with_board() {
    plc::Profile p = plc::cj2h();
    p.loop_control = true;
    return p;
}

struct Answer {
    std::uint16_t end_code = 0xFFFF;
    std::string data;
};

// Runs the 02 40 handler on `parameters` (hex) with no frame around it.
Answer call(plc::Plc& plc, std::string_view parameters) {
    const auto* entry = server::handlers::find_handler(FunctionBlockItemRead::code);
    if (entry == nullptr) return {};
    const Header header{};
    const server::RequestContext request{};
    server::handlers::HandlerContext context{plc, header, request};
    std::array<std::uint8_t, max_response_data_size> buffer{};
    ByteWriter out(buffer);
    const auto params = hex(parameters);
    const auto code = entry->function(context, params, out);
    return {static_cast<std::uint16_t>(code),
            code == EndCode::normal_completion ? to_hex(out.written()) : ""};
}

TEST(FunctionBlockItemRead, Seed001_ReadsRegisteredItemsInRequestOrder) {
    plc::Plc plc{with_board()};
    // Basic PID block 2: PV = 4000 + 500 x 2, SP = 5000 + 100 x 2, run time 3600 x 2 s.
    const auto a = call(plc, "0002 0004 0006 0007 0014 001E");
    EXPECT_EQ(a.end_code, 0x0000);
    EXPECT_EQ(a.data, to_hex(hex("0004 0006 02 1388  0007 02 1450  0014 01 00  001E 04 00001C20")));
    const auto common = call(plc, "0000 0002 0000 000A");
    EXPECT_EQ(common.data, to_hex(hex("0002 0000 02 0000 000A 04 00015180")));
}

TEST(FunctionBlockItemRead, Seed001_NormalWhenAtLeastOneItemIsRead) {
    plc::Plc plc{with_board()};
    // ITEM 099 is not in the block, 03E8 is out of range: both left out.
    const auto a = call(plc, "0001 0003 0063 0000 03E8");
    EXPECT_EQ(a.end_code, 0x0000);
    EXPECT_EQ(a.data, to_hex(hex("0001 0000 02 000B")));
}

TEST(FunctionBlockItemRead, Seed001_1103WhenNoItemIsValid) {
    plc::Plc plc{with_board()};
    EXPECT_EQ(call(plc, "0001 0002 0063 03E8").end_code, 0x1103);
    // Step Ladder Program block: the sequence commands from ITEM 011 on are not readable.
    EXPECT_EQ(call(plc, "0064 0002 000B 0014").end_code, 0x1103);
    const auto step = call(plc, "0064 0002 0008 000B");
    EXPECT_EQ(step.end_code, 0x0000);
    EXPECT_EQ(step.data, to_hex(hex("0001 0008 02 0001")));
}

TEST(FunctionBlockItemRead, Seed001_1101UnusableOrUnregisteredBlock) {
    plc::Plc plc{with_board()};
    EXPECT_EQ(call(plc, "0005 0001 0000").end_code, 0x1101);  // not registered
    EXPECT_EQ(call(plc, "03E8 0001 0000").end_code, 0x1101);  // beyond 999
    EXPECT_EQ(call(plc, "FFFF 0001 0000").end_code, 0x1101);
}

TEST(FunctionBlockItemRead, Seed001_110CZeroItems) {
    plc::Plc plc{with_board()};
    EXPECT_EQ(call(plc, "0001 0000").end_code, 0x110C);
}

TEST(FunctionBlockItemRead, Seed001_CommandLengthCodes) {
    plc::Plc plc{with_board()};
    EXPECT_EQ(call(plc, "0001 00").end_code, 0x1002);
    EXPECT_EQ(call(plc, "").end_code, 0x1002);
    EXPECT_EQ(call(plc, "0001 0002 0006").end_code, 0x1003);
    std::string long_command = "0001 03E7";
    for (int i = 0; i < 999; ++i)
        long_command += "0006";
    EXPECT_EQ(call(plc, long_command).end_code, 0x1001);
}

TEST(FunctionBlockItemRead, Seed001_110BReadDataOver968Bytes) {
    plc::Plc plc{with_board()};
    // Run time (ITEM 030) is 4 bytes: 3 + 4 = 7 bytes per ITEM; 138 fit (966), 139 not.
    std::string fits = "0001 008A";
    for (int i = 0; i < 138; ++i)
        fits += "001E";
    EXPECT_EQ(call(plc, fits).end_code, 0x0000);
    std::string over = "0001 008B";
    for (int i = 0; i < 139; ++i)
        over += "001E";
    EXPECT_EQ(call(plc, over).end_code, 0x110B);
}

TEST(FunctionBlockItemRead, Seed001_WithoutALoopControlBoardTheCommandIsUndefined) {
    plc::Plc plc{plc::cj2h()};
    EXPECT_EQ(call(plc, "0001 0001 0006").end_code, 0x0401);
    EXPECT_EQ(call(plc, "00").end_code, 0x0401);  // before any length check
}

// 02 40 is a Loop Control Board command (seed 001): the board is the Inner Board,
// unit E1 (frames 1.4), and answers from there.
TEST(FunctionBlockItemRead, Seed001_ThroughFullFramesToTheInnerBoard) {
    FrameFields board;
    board.destination.unit = inner_board_unit;
    Harness h{with_board()};
    const auto r = h.send("0240 0001 0001 0006", board);
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.header().source.unit, inner_board_unit);
    EXPECT_EQ(r.data_hex(), to_hex(hex("0001 0006 02 1194")));
    EXPECT_EQ(h.send("0240 0001 0000", board).end_code(), 0x110C);
    Harness plain;
    EXPECT_EQ(plain.send("0240 0001 0001 0006", board).end_code(), 0x0202);  // no board
}

// Choice pinned: the CPU Unit itself does not know 02 40, and the board knows nothing
// but it here (0401 either way).
TEST(FunctionBlockItemRead, Seed001_CpuUnitAndBoardEachAnswerOnlyTheirCommands) {
    FrameFields board;
    board.destination.unit = inner_board_unit;
    Harness h{with_board()};
    EXPECT_EQ(h.send("0240 0001 0001 0006").end_code(), 0x0401);
    EXPECT_EQ(h.send("0101 82000000 0001", board).end_code(), 0x0401);
    EXPECT_EQ(h.send("0101 82000000 0001").end_code(), 0x0000);
}

}  // namespace
}  // namespace fins::test
