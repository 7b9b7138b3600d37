// The control channel's scenario verb (issue 19; docs/scenarios.md):
//   {"cmd":"scenario","action":"status"}                 -> {"ok":true,"scenario":{...}}
//   {"cmd":"scenario","action":"pause"} / "resume"       time stops / goes on
//   {"cmd":"scenario","action":"advance","seconds":2.5}  runs 2.5 s of scenario time now
//                                                        (in slices: FINS requests are
//                                                        served meanwhile; answers when
//                                                        done)
//   {"cmd":"scenario","action":"trigger","event":"jam"}  starts the event now
//   {"cmd":"scenario","action":"reload"}                 reads the file again; a bad file
//                                                        keeps the running scenario and
//                                                        the error says why
// A CPU Unit without a scenario answers {"error":"... runs no scenario ..."}. While an
// advance runs, pause, resume, advance, trigger and reload answer {"error":"an advance is
// running (N of M ticks done): wait for its answer"}; status answers, with
// "advancing":{"ticks_done":N,"ticks":M}.
#pragma once

#include <functional>

#include <nlohmann/json.hpp>

namespace fins::server {

class ScenarioControl;

// The answer to a request whose "cmd" is "scenario"; `scenario` may be null. An advance
// runs in one piece here.
nlohmann::json handle_scenario_request(ScenarioControl* scenario, const nlohmann::json& request);
// The same, answered through `reply` (called once): an advance runs in slices
// (ScenarioControl::advance_async) and answers when its ticks have run.
void handle_scenario_request(ScenarioControl* scenario, const nlohmann::json& request,
                             const std::function<void(nlohmann::json)>& reply);

}  // namespace fins::server
