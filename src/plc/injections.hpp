// Conditions an engineer injects into the virtual CPU Unit that no FINS command can
// cause: a low battery, FAL/FALS errors as if the user program had executed FAL(006)
// or FALS(007), MSG(046) messages, and any other error code of W342 5-3-27. Filled from
// the [faults]-style section of the finsd configuration file (or by hand in tests) and
// applied once at start-up; the control channel (server/control/control.hpp) injects the same
// conditions at run time.
//
// Data only: no parsing here. validate() names the first bad field so the
// configuration loader can refuse the file; apply() skips what validate() rejects.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fins::plc {

class Plc;

struct FalInjection {
    std::uint16_t number = 0;  // FAL/FALS number, 1-511 (error code 4100+n / C100+n)
    std::string message;       // up to 16 ASCII characters (5-3-23), may be empty
};

struct Injections {
    // The battery is low: non-fatal battery error 00F7 (06 01 non-fatal bit 4, end-code
    // flag 0040 on every response); it recurs after ERROR CLEAR while this stays set.
    bool battery_error = false;
    // FAL errors (non-fatal, 06 01 non-fatal bit 15, end-code flag 0040), in order.
    std::vector<FalInjection> fal;
    // One FALS error (fatal, 06 01 fatal bit 6, end-code flag 0080): the CPU stops
    // running; only ERROR CLEAR in PROGRAM mode removes it.
    std::optional<FalInjection> fals;
    // MSG 0-7 texts, up to 32 ASCII characters each; nullopt = not registered.
    std::array<std::optional<std::string>, 8> messages;
    // Any other error code of W342 5-3-27, e.g. 0x0203 (CPU Bus Unit 3 error) or 0x80F0
    // (program error, fatal). FAL/FALS codes belong in `fal`/`fals`.
    std::vector<std::uint16_t> errors;
};

// "" when every field is in range, else a message naming the first bad field, e.g.
// "fal[1].number: 600 is not 1-511".
std::string validate(const Injections& injections);

// Raises the errors and registers the messages on `plc`, logging each new error at
// `now`. Invalid entries (see validate()) are skipped.
void apply(const Injections& injections, Plc& plc, std::chrono::system_clock::time_point now);

}  // namespace fins::plc
