// The control channel's scenario verb (issue 19; docs/scenarios.md):
//   {"cmd":"scenario","action":"status"}                 -> {"ok":true,"scenario":{...}}
//   {"cmd":"scenario","action":"pause"} / "resume"       time stops / goes on
//   {"cmd":"scenario","action":"advance","seconds":2.5}  runs 2.5 s of scenario time now
//   {"cmd":"scenario","action":"trigger","event":"jam"}  starts the event now
//   {"cmd":"scenario","action":"reload"}                 reads the file again; a bad file
//                                                        keeps the running scenario and
//                                                        the error says why
// A CPU Unit without a scenario answers {"error":"... runs no scenario ..."}.
#pragma once

#include <nlohmann/json.hpp>

namespace fins::server {

class ScenarioControl;

// The answer to a request whose "cmd" is "scenario"; `scenario` may be null.
nlohmann::json handle_scenario_request(ScenarioControl* scenario, const nlohmann::json& request);

}  // namespace fins::server
