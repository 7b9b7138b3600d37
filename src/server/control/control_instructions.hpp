// The control channel's PLC-initiated message verbs (control.cpp hands them here):
//
//   {"cmd":"send","dest":"0.5.0","local":"D100","remote":"D200","count":10,
//    "timeout":20,"retries":2,"no_response":false}
//   {"cmd":"recv", ... same keys: reads `count` words at `remote` into `local`}
//   {"cmd":"sendcmd","dest":"0.5.0","command":"0501", "timeout" ...}
//   {"cmd":"instructions"}   the engine's state: ports in use, counters, and each
//                            [[schedule]] entry's runs, done, errors, skipped ticks
//
// An instruction answers when it completes (so a reply may take timeout x (retries + 1)):
//   {"ok":true|false,"result":{"instruction":"send","done":true,"error_id":"0000",
//    "error_id_ex":"0000","end_code":"0000","port":0,"transmissions":1,
//    "words":[...] (recv), "response":"0501...." (sendcmd), "detail":"..."},
//    "error":"..." (when not done)}
// A request that cannot be read (missing or mistyped keys) answers {"error":"..."} at once.
#pragma once

#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

namespace fins::server {

class NetworkInstructions;
class InstructionSchedule;
struct ScheduleEntry;

using ControlReply = std::function<void(nlohmann::json)>;

// True when `request` is one of the verbs above; `reply` is then called exactly once
// (maybe later, on the io_context). False leaves the request to the caller.
bool handle_instruction_request(NetworkInstructions* engine,
                                const std::vector<ScheduleEntry>& schedule,
                                const nlohmann::json& request, const ControlReply& reply);

}  // namespace fins::server
