// GET /api/scenario: the running scenario of a CPU Unit as the page's Scenario panel
// shows it: its status (what `finsd ctl scenario status` answers), its tags with their
// addresses and types, the addresses it reads, and its events with their state.
// Its actions (pause, resume, advance, trigger) are POST /api/control
// {"cmd":"scenario",...}, under that route's rules.
#pragma once

#include <cstddef>

#include <nlohmann/json.hpp>

#include "server/control/control.hpp"

namespace fins::web {

// At most this many tags are listed ("tags_total" says how many there are).
inline constexpr std::size_t max_listed_tags = 2000;

// The object of GET /api/scenario for `target`; null when it runs no scenario.
nlohmann::json scenario_object(const server::ControlTarget& target);

}  // namespace fins::web
