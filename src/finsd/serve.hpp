// finsd's one composition root (docs/architecture.md "finsd: one start-up"): whatever
// the configuration describes, a single node (the top-level keys) or a plant ([[plc]]
// tables), is started, served and stopped by serve():
//
//   open the CPU Units: each one's state file (or the heap) -> Plc -> operating mode ->
//     file memory -> its Ethernet units bound (serve_single.cpp, serve_plant.cpp)
//   each CPU Unit: [memory] -> [protection], [inject] -> Serial Gateway ports ->
//     scenario -> Host Link ports -> [[schedule]] (serve_cpu.cpp)
//   the web front (--http) -> the control channel -> SIGINT/SIGTERM handled ->
//   "listening <port>" on stdout -> every state file checked once a second -> run
//
// Exit codes (docs/finsd.md): 0 clean shutdown (SIGINT/SIGTERM: every state file closed
// cleanly, with checksums), 2 usage or configuration error, 3 start-up failure (cannot
// bind, state file refused, in use or without room on disk, control socket), 4 a state
// file shrank while finsd ran (truncated from outside: plc/storage/storage_guard.hpp),
// a single node's or any CPU Unit's of a plant.
#pragma once

#include "finsd/config.hpp"

namespace fins::finsd {

// Serves `settings` (configured and validated) until a signal or a lost state file;
// returns finsd's exit code. Logs at settings.log_level on the default logger.
int serve(const Settings& settings);

}  // namespace fins::finsd
