// The FINS command set of W342 5-1-1 with the execution conditions of 5-1-2, as data.
// Client (names, CLI help) and server (which commands exist, when they may run) both
// read this one table.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "fins/frame.hpp"

namespace fins {

// One row of W342 5-1-2: true = "OK" (accepted), false = "Disabled" (refused).
struct ExecutionConditions {
    bool run = true;                       // accepted in RUN mode
    bool monitor = true;                   // accepted in MONITOR mode
    bool program = true;                   // accepted in PROGRAM mode
    bool access_right_elsewhere = true;    // accepted while another device holds the access right
    bool um_read_protected = true;         // accepted while UM read protection is on
    bool dip_write_protected = true;       // accepted while DIP pin 1 write-protects UM
    bool network_write_protected = true;   // accepted while FINS write protection via network is on
};

struct CommandInfo {
    CommandCode code;
    std::string_view name;     // the manual's name, e.g. "MEMORY AREA READ"
    std::string_view section;  // e.g. "5-3-2"
    ExecutionConditions conditions;
};

// Every command of W342 section 5, ascending by code (22 xx and 28 xx included).
std::span<const CommandInfo> command_table() noexcept;
const CommandInfo* find_command(CommandCode code) noexcept;

}  // namespace fins
