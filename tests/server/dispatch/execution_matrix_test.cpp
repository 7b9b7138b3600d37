// The execution-condition table of W342 5-1-2, exhaustively: every command finsd
// implements x every operating mode x every protection / access-right condition, each
// through a full frame into a fresh virtual PLC. A condition the table marks "Disabled"
// must be refused with its end code before the handler runs (so even a command with no
// parameters gets that code, not 1002); one marked "OK" must never produce it.
#include <string>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "fins/command_table.hpp"
#include "server/frame_builder.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::test {
namespace {

enum class Condition { run, monitor, program, access_right, um_read, dip_write, network_write };

struct Case {
    Condition condition;
    const char* name;
    std::uint16_t refusal;  // end code when the table says Disabled
};

constexpr Case cases[] = {
    {Condition::run, "RUN mode", 0x2206},
    {Condition::monitor, "MONITOR mode", 0x2205},
    {Condition::program, "PROGRAM mode", 0x2203},
    {Condition::access_right, "access right at another node", 0x3001},
    {Condition::um_read, "UM read protection", 0x2002},
    {Condition::dip_write, "DIP switch UM write protection", 0x2101},
    {Condition::network_write, "network write protection", 0x2102},
};

bool accepted(const ExecutionConditions& c, Condition condition) {
    switch (condition) {
        case Condition::run:
            return c.run;
        case Condition::monitor:
            return c.monitor;
        case Condition::program:
            return c.program;
        case Condition::access_right:
            return c.access_right_elsewhere;
        case Condition::um_read:
            return c.um_read_protected;
        case Condition::dip_write:
            return c.dip_write_protected;
        case Condition::network_write:
            return c.network_write_protected;
    }
    return true;
}

// The PLC in `condition` only: the protections and the access right are tried in
// PROGRAM mode when the command refuses RUN, so that the mode does not answer first.
void set_up(plc::Plc& plc, Condition condition, const ExecutionConditions& row) {
    const auto base = row.run ? plc::OperatingMode::run : plc::OperatingMode::program;
    plc.set_mode(base);
    switch (condition) {
        case Condition::run:
            plc.set_mode(plc::OperatingMode::run);
            break;
        case Condition::monitor:
            plc.set_mode(plc::OperatingMode::monitor);
            break;
        case Condition::program:
            plc.set_mode(plc::OperatingMode::program);
            break;
        case Condition::access_right:
            plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});  // not the sender
            break;
        case Condition::um_read:
            plc.set_um_read_protection(true);
            break;
        case Condition::dip_write:
            plc.set_dip_write_protection(true);
            break;
        case Condition::network_write:
            plc.set_network_write_protection(true);
            break;
    }
}

TEST(ExecutionMatrix, W342_5_1_2_EveryCommandEveryModeEveryCondition) {
    int checked = 0;
    for (const auto& entry : server::handlers::handler_table()) {
        const CommandInfo* info = find_command(entry.code);
        ASSERT_NE(info, nullptr);
        FrameFields fields;
        plc::Profile profile = plc::cj2h();
        if (entry.code == CommandCode{0x02, 0x40}) {
            // The Loop Control Board's command goes to the Inner Board (unit E1).
            profile = *plc::find_profile("cs1h-lcb");
            fields.destination.unit = inner_board_unit;
        }
        // The Memory Cassette command exists on the CP1H only (5-1-1).
        if (entry.code == CommandCode{0x22, 0x20}) profile = *plc::find_profile("cp1h");
        for (const auto& c : cases) {
            SCOPED_TRACE(fmt::format("{:04X} {} / {}", entry.code.value(), info->name, c.name));
            Harness h{profile};
            set_up(h.plc, c.condition, info->conditions);
            // 0C 01 checks the access right in its handler, after decoding FFFF.
            const std::string hex =
                fmt::format("{:04X}{}", entry.code.value(),
                            entry.code == CommandCode{0x0C, 0x01} ? "FFFF" : "");
            const auto end_code = h.send(hex, fields).end_code() & 0x7F3F;
            // 0C 01's row is accepted so that its handler can name the holder; the
            // manual's "Disabled" still holds, the handler answers 3001 itself.
            const bool handler_refuses =
                entry.code == CommandCode{0x0C, 0x01} && c.condition == Condition::access_right;
            if (accepted(info->conditions, c.condition) && !handler_refuses)
                EXPECT_NE(end_code, c.refusal);
            else
                EXPECT_EQ(end_code, c.refusal);
            ++checked;
        }
    }
    // Every registered command went through all seven conditions.
    EXPECT_EQ(checked, static_cast<int>(server::handlers::handler_table().size() * 7));
}

// Where a command's own page decides against the 5-1-2 matrix (command_table.cpp rows
// marked "Page decides"): the row departs from 5-1-2 on that condition, and finsd
// answers as the page says.
struct PageDecides {
    CommandCode code;
    Condition condition;
    bool matrix_says_ok;  // the 5-1-2 value the row departs from
    const char* pages;
};

constexpr PageDecides page_decides[] = {
    // 5-1-2: OK. 5-3-29 "No"; 5-3-24 / 5-3-25 lists: 2103 "No".
    {{0x21, 0x03}, Condition::access_right, true, "5-3-29, 5-3-24, 5-3-25"},
    // 5-1-2: Disabled for the whole row. 5-3-21 MESSAGE READ and 5-3-23 FAL/FALS READ:
    // OK; MESSAGE CLEAR stays refused, by the 09 20 handler.
    {{0x09, 0x20}, Condition::network_write, false, "5-3-21, 5-3-23"},
};

TEST(ExecutionMatrix, W342_5_1_2_PageDecidesExceptions) {
    for (const auto& e : page_decides) {
        const CommandInfo* info = find_command(e.code);
        ASSERT_NE(info, nullptr);
        SCOPED_TRACE(fmt::format("{:04X} {} ({})", e.code.value(), info->name, e.pages));
        EXPECT_NE(accepted(info->conditions, e.condition), e.matrix_says_ok);
    }
    {  // 21 03 under another node's access right: 3001, the log is kept.
        Harness h;
        h.plc.errors().raise(0x0201, {});
        set_up(h.plc, Condition::access_right, find_command({0x21, 0x03})->conditions);
        EXPECT_EQ(h.send("2103").end_code() & 0x7F3F, 0x3001);
        EXPECT_EQ(h.plc.errors().log_size(), 1u);
    }
    {  // 09 20 under network write protection: both reads answer, CLEAR is 2102.
        Harness h;
        set_up(h.plc, Condition::network_write, find_command({0x09, 0x20})->conditions);
        EXPECT_EQ(h.send("0920 0001").end_code(), 0x0000);  // MESSAGE READ
        EXPECT_EQ(h.send("0920 8001").end_code(), 0x0000);  // FAL/FALS READ
        EXPECT_EQ(h.send("0920 4001").end_code(), 0x2102);  // MESSAGE CLEAR
    }
}

// Every command of W342 section 5 outside file memory (22 xx) and the serial gateway
// (28 xx) has a handler, and so went through the matrix above.
TEST(ExecutionMatrix, W342_5_1_1_EveryNonFileCommandIsImplemented) {
    for (const auto& c : command_table()) {
        if (c.code.main == 0x22 || c.code.main == 0x28) continue;
        EXPECT_NE(server::handlers::find_handler(c.code), nullptr) << c.name;
    }
}

}  // namespace
}  // namespace fins::test
