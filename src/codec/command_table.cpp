// The command list of W342 5-1-1 with the execution conditions of 5-1-2.
//
// Where 5-1-2 disagrees with a command's own "Execution Conditions" table in 5-3, this
// table follows 5-1-2 and says so next to the row, so a handler can decide knowingly;
// rows marked "Page decides" follow the command's own page(s) instead (tests/server/dispatch/
// execution_matrix_test.cpp lists them).
#include "fins/command_table.hpp"

#include <algorithm>
#include <array>

namespace fins {
namespace {

constexpr bool OK = true;
constexpr bool NO = false;  // "Disabled" in 5-1-2

// Columns of 5-1-2, in order: RUN, MONITOR, PROGRAM, access right held elsewhere,
// UM read protection, DIP switch UM write protection, write-protected from network.
constexpr ExecutionConditions when(bool run, bool monitor, bool program, bool access,
                                   bool read_protect, bool dip, bool network) {
    return {run, monitor, program, access, read_protect, dip, network};
}
constexpr ExecutionConditions always = when(OK, OK, OK, OK, OK, OK, OK);
// Commands that change I/O memory only: refused just by network write protection.
constexpr ExecutionConditions memory_write = when(OK, OK, OK, OK, OK, OK, NO);
// Commands that need the access right and respect network write protection.
constexpr ExecutionConditions guarded_write = when(OK, OK, OK, NO, OK, OK, NO);

constexpr std::array commands{
    CommandInfo{{0x01, 0x01}, "MEMORY AREA READ", "5-3-2", always},
    CommandInfo{{0x01, 0x02}, "MEMORY AREA WRITE", "5-3-3", memory_write},
    CommandInfo{{0x01, 0x03}, "MEMORY AREA FILL", "5-3-4", memory_write},
    CommandInfo{{0x01, 0x04}, "MULTIPLE MEMORY AREA READ", "5-3-5", always},
    CommandInfo{{0x01, 0x05}, "MEMORY AREA TRANSFER", "5-3-6", memory_write},
    CommandInfo{{0x02, 0x01}, "PARAMETER AREA READ", "5-3-7", always},
    CommandInfo{{0x02, 0x02}, "PARAMETER AREA WRITE", "5-3-8", when(OK, OK, OK, NO, OK, NO, NO)},
    CommandInfo{{0x02, 0x03}, "PARAMETER AREA CLEAR", "5-3-9", when(OK, OK, OK, NO, OK, NO, NO)},
    // Loop Control Board command (seed 001); a read, accepted in every state.
    CommandInfo{{0x02, 0x40}, "READ MULTIPLE ITEMS FROM FUNCTION BLOCK", "seed 001", always},
    CommandInfo{{0x03, 0x06}, "PROGRAM AREA READ", "5-3-10", when(OK, OK, OK, OK, NO, OK, OK)},
    CommandInfo{{0x03, 0x07}, "PROGRAM AREA WRITE", "5-3-11", when(NO, NO, OK, NO, OK, NO, NO)},
    CommandInfo{{0x03, 0x08}, "PROGRAM AREA CLEAR", "5-3-12", when(NO, NO, OK, NO, OK, NO, NO)},
    CommandInfo{{0x04, 0x01}, "RUN", "5-3-13", guarded_write},
    CommandInfo{{0x04, 0x02}, "STOP", "5-3-14", guarded_write},
    CommandInfo{{0x05, 0x01}, "CPU UNIT DATA READ", "5-3-15", always},
    CommandInfo{{0x05, 0x02}, "CONNECTION DATA READ", "5-3-16", always},
    CommandInfo{{0x06, 0x01}, "CPU UNIT STATUS READ", "5-3-17", always},
    CommandInfo{{0x06, 0x20}, "CYCLE TIME READ", "5-3-18", when(OK, OK, NO, OK, OK, OK, OK)},
    CommandInfo{{0x07, 0x01}, "CLOCK READ", "5-3-19", always},
    // 5-1-2 leaves the network column blank; 5-3-20 says "No" and W596 2-6 lists CLOCK
    // WRITE as refused under write protection.
    CommandInfo{{0x07, 0x02}, "CLOCK WRITE", "5-3-20", guarded_write},
    // Page decides: 5-1-2 gives one row for the three variants, access right "Disabled
    // (MESSAGE CLEAR only)" and network write protection "Disabled". 5-3-21 MESSAGE READ
    // and 5-3-23 FAL/FALS READ say OK under both: they are reads. So the row accepts
    // both and the 09 20 handler refuses MESSAGE CLEAR itself (2102 under network write
    // protection, as 5-1-2 says; 3001 while another node holds the access right, 5-3-22)
    // and marks it as a write for the FINS write access log.
    CommandInfo{{0x09, 0x20}, "MESSAGE READ/CLEAR", "5-3-21", always},
    // 5-1-2 marks 0C 01 "Disabled" while another device holds the right; the handler
    // refuses it itself so that its 3001 answer can name the holder (5-3-24).
    CommandInfo{{0x0C, 0x01}, "ACCESS RIGHT ACQUIRE", "5-3-24", when(OK, OK, OK, OK, OK, OK, NO)},
    CommandInfo{{0x0C, 0x02}, "ACCESS RIGHT FORCED ACQUIRE", "5-3-25", always},
    CommandInfo{{0x0C, 0x03}, "ACCESS RIGHT RELEASE", "5-3-26", always},
    // 5-3-27 gives "OK" for network write protection; 5-1-2 (and 5-1-1 note 1) Disabled.
    CommandInfo{{0x21, 0x01}, "ERROR CLEAR", "5-3-27", guarded_write},
    CommandInfo{{0x21, 0x02}, "ERROR LOG READ", "5-3-28", always},
    // Page decides: 5-3-29 ("Access right at other device: No") and the lists of
    // commands refused while another device holds the access right on the 0C 01 and
    // 0C 02 pages (5-3-24, 5-3-25: "2103 ERROR LOG CLEAR") say 3001; only 5-1-2 says OK.
    CommandInfo{{0x21, 0x03}, "ERROR LOG CLEAR", "5-3-29", guarded_write},
    CommandInfo{{0x21, 0x40}, "FINS WRITE ACCESS LOG READ", "5-3-30", always},
    CommandInfo{{0x21, 0x41}, "FINS WRITE ACCESS LOG CLEAR", "5-3-31", guarded_write},
    CommandInfo{{0x22, 0x01}, "FILE NAME READ", "5-3-32", always},
    CommandInfo{{0x22, 0x02}, "SINGLE FILE READ", "5-3-33", always},
    CommandInfo{{0x22, 0x03}, "SINGLE FILE WRITE", "5-3-34", guarded_write},
    CommandInfo{{0x22, 0x04}, "FILE MEMORY FORMAT", "5-3-35", guarded_write},
    CommandInfo{{0x22, 0x05}, "FILE DELETE", "5-3-36", guarded_write},
    CommandInfo{{0x22, 0x07}, "FILE COPY", "5-3-37", guarded_write},
    CommandInfo{{0x22, 0x08}, "FILE NAME CHANGE", "5-3-38", guarded_write},
    CommandInfo{{0x22, 0x0A}, "MEMORY AREA-FILE TRANSFER", "5-3-39", guarded_write},
    // Notes 1-3 of 5-1-2: in RUN/MONITOR (22 0B, 22 0C) and under DIP write protection
    // (22 0B) only the area-to-file direction is possible; the handler refuses the
    // file-to-area direction. 22 0C under DIP protection: only program-to-file works,
    // so its DIP column is OK here and the handler refuses file-to-program (2101).
    CommandInfo{{0x22, 0x0B}, "PARAMETER AREA-FILE TRANSFER", "5-3-40", guarded_write},
    CommandInfo{{0x22, 0x0C}, "PROGRAM AREA-FILE TRANSFER", "5-3-41", guarded_write},
    CommandInfo{{0x22, 0x15}, "CREATE/DELETE DIRECTORY", "5-3-42", guarded_write},
    // Note 4: with DIP protection, cassette contents with program data cannot be loaded.
    CommandInfo{
        {0x22, 0x20}, "MEMORY CASSETTE TRANSFER", "5-3-43", when(NO, NO, OK, NO, OK, OK, NO)},
    CommandInfo{{0x23, 0x01}, "FORCED SET/RESET", "5-3-44", when(NO, OK, OK, OK, OK, OK, NO)},
    CommandInfo{
        {0x23, 0x02}, "FORCED SET/RESET CANCEL", "5-3-45", when(NO, OK, OK, OK, OK, OK, NO)},
    CommandInfo{{0x28, 0x03}, "CONVERT TO COMPOWAY/F COMMAND", "5-3-46", always},
    CommandInfo{{0x28, 0x04}, "CONVERT TO MODBUS-RTU COMMAND", "5-3-47", always},
    CommandInfo{{0x28, 0x05}, "CONVERT TO MODBUS-ASCII COMMAND", "5-3-48", always},
};

constexpr bool ascending() {
    for (std::size_t i = 1; i < commands.size(); ++i)
        if (commands[i - 1].code.value() >= commands[i].code.value()) return false;
    return true;
}
static_assert(ascending(), "find_command() needs the table sorted by command code");

}  // namespace

std::span<const CommandInfo> command_table() noexcept {
    return commands;
}

const CommandInfo* find_command(CommandCode code) noexcept {
    const auto it = std::lower_bound(
        commands.begin(), commands.end(), code.value(),
        [](const CommandInfo& info, std::uint16_t value) { return info.code.value() < value; });
    if (it == commands.end() || it->code != code) return nullptr;
    return &*it;
}

}  // namespace fins
