// `finsd ctl send|recv|sendcmd|instructions`: PLC-initiated messages (W596 3) run by a
// running finsd (server/control/control_instructions.hpp).
//
//   send    --dest N.N.U --local D100 --remote D200 [--count 1]   local words -> remote
//   recv    --dest N.N.U --remote D200 --local D300 [--count 1]   remote words -> local
//   sendcmd --dest N.N.U --command "0501"                         any command, its answer
//   common: [--timeout SECONDS (as fins: 0.5 = 0.5 s; 0 = 2 s)] [--retries R (0-15)]
//           [--no-response] [--json]
//   instructions                                                  ports in use, counters
// `send JSON` (a single argument starting with '{') still sends one raw request line.
//
// Exit codes of send/recv/sendcmd: 0 Done; 2 usage or a parameter out of range
// (ErrorID 0400); 3 no control channel; 4 the remote answered an end code other than
// normal (0800 + the end code); 5 no response (0800 0205); 6 not sent (0800: 0104 32
// instructions running, 0501 no address, 0101 no UDP port, 0103 send failed).
#pragma once

#include <chrono>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace fins::finsd {

struct InstructionVerbs {
    CLI::App* send = nullptr;
    CLI::App* recv = nullptr;
    CLI::App* sendcmd = nullptr;
    std::string raw;  // `send JSON`
    bool json = false;
    // How long the answer may take: the instruction's timeout x (retries + 1) + 5 s.
    std::chrono::milliseconds wait{5000};
};

// Adds the verbs; their callbacks fill `request` (and verbs.wait).
void add_instruction_verbs(CLI::App& app, nlohmann::json& request, InstructionVerbs& verbs);
// Prints an instruction's answer (text, or the JSON line with --json) and returns the
// exit code above.
int print_instruction_answer(const nlohmann::json& answer, const std::string& line, bool json);

}  // namespace fins::finsd
