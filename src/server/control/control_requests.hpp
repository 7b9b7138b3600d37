// The control channel's PLC verbs (control.cpp reads the lines and hands each request
// object here; control_instructions.hpp takes the PLC-initiated message verbs):
//   {"cmd":"status"}                                -> {"ok":true,"status":{...}}
//   {"cmd":"battery_error","on":true}               low battery: error 00F7 (flag 0040)
//   {"cmd":"fal","number":5,"message":"TEXT"}       FAL 5 (non-fatal, code 4105)
//   {"cmd":"fals","number":5,"message":"TEXT"}      FALS 5 (fatal, code C105, CPU stops)
//   {"cmd":"error","code":"0203"}                   any other W342 5-3-27 code (hex text
//                                                   or a number)
//   {"cmd":"clear_errors"}                          every error and the battery cause;
//   {"cmd":"clear_errors","code":"4105"}            or just one code (no mode rules)
//   {"cmd":"message","number":3,"text":"TEXT"}      registers MSG 3; no "text" (or
//                                                   null) unregisters it
//   {"cmd":"network_write_protection","on":true}    PLC Setup write protection (all nodes)
//   {"cmd":"um_read_protection","on":false,"password":"..."}  UM read protection
//   {"cmd":"mode","mode":"program"}                 program, monitor or run
//   {"cmd":"release_access_right"}                  as 0C 03 from any node
//   {"cmd":"card","inserted":true,"kbytes":30720}   inserts (capacity in KB, default the
//                                                   profile's or 30720) or removes the card
//   {"cmd":"cassette","inserted":false}             removes (or mounts) the CP1H Memory
//                                                   Cassette; other profiles: an error
// Anything else answers {"error":"..."}.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace fins::plc {
class Plc;
enum class OperatingMode : std::uint8_t;
}  // namespace fins::plc

namespace fins::server {

// {"error": message}
nlohmann::json control_error(const std::string& message);

// "program", "monitor" or "run": the mode as the control status and the web API name it.
const char* mode_name(plc::OperatingMode m) noexcept;

// One request object with a string "cmd" -> its answer. Throws only what nlohmann::json
// throws for a mistyped key (the caller answers "bad request: ...").
nlohmann::json handle_control_request(plc::Plc& plc, const nlohmann::json& request);

}  // namespace fins::server
