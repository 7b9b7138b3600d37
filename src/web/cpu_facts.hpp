// What the page shows of a CPU Unit beyond the control channel's status object: its
// memory areas at this model's sizes (the profile is their one source), its clock and
// its cycle times. Chosen so that an idle PLC's status does not change: the clock is an
// offset the page adds to its own clock (it moves only when 07 02 sets the clock), the
// cycle time the model's base cycle with the maximum and minimum of 06 20, which settle
// within a few cycles (the average of the last 8 cycles would change every cycle and
// wake every page's status subscription).
#pragma once

#include <chrono>

#include <nlohmann/json.hpp>

namespace fins::plc {
class Plc;
struct Profile;
}  // namespace fins::plc

namespace fins::web {

// [{"prefix":"CIO","words":6144}, ..., {"prefix":"E0_","words":32768}, ...]: the areas
// of `profile` a word address names (fins::parse_address prefixes), in the order
// engineers list them.
nlohmann::json memory_areas(const plc::Profile& profile);

// Adds "clock_offset_s" (the CPU Unit clock minus UTC, seconds: the page shows
// now + offset as a UTC time) and "cycle_time": {"base_ms", "max_ms", "min_ms"} (0 until
// a cycle completed) to `status`, as of `now`: what 06 20 answers at that time. Reads
// only: the scan cycle runs from the CPU Unit's power-on whether anyone asks or not.
void add_cpu_facts(plc::Plc& plc, nlohmann::json& status,
                   std::chrono::system_clock::time_point now);

}  // namespace fins::web
