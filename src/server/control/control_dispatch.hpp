// One dispatcher for every control front end: the Unix socket (control.cpp) and finsd's
// HTTP API (`POST /api/control`, src/web/) hand each request object here, so both take
// the same verbs (control_requests.hpp, control_instructions.hpp), choose the CPU Unit by
// the same "plc" rule and answer the same objects.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

#include "server/control/control.hpp"
#include "server/control/control_instructions.hpp"

namespace fins::server {

// "NET.NODE" -> (network, node); nullopt for anything else.
std::optional<std::pair<std::uint8_t, std::uint8_t>> parse_net_node(std::string_view text);

// The CPU Unit `wanted` names: a [[plc]] name or one of its FINS addresses "NET.NODE";
// nullopt: the first. nullptr with the reason in `why` when none matches.
const ControlTarget* find_control_target(std::span<const ControlTarget> targets,
                                         std::optional<std::string_view> wanted, std::string& why);

// Answers `request` (an object with a string "cmd", any "plc"): `reply` is called exactly
// once, at once for the PLC verbs and errors, when the instruction completes for send /
// recv / sendcmd (later, on the io_context). A "status" answer of a named CPU Unit
// carries its name as status.plc.
//
// The failure boundary of both channels (sessions/failure_boundary.hpp): whatever a verb
// throws, other than nlohmann::json's exceptions for a mistyped key ({"error":"bad
// request: ..."}), answers {"error":"internal error: WHAT","internal":true} (HTTP 500), counts in
// fins_control_failures_total and logs (rate-limited); nothing escapes to the io_context.
void dispatch_control_request(std::span<const ControlTarget> targets, const nlohmann::json& request,
                              const ControlReply& reply);

// Test seam: when set, called with each request inside the boundary before the verb, so
// a test can make a request throw. Null (the default): nothing.
using ControlFault = void (*)(const nlohmann::json& request);
void set_control_fault_for_tests(ControlFault fault) noexcept;

}  // namespace fins::server
