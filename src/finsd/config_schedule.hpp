// finsd's [[remote]] and [[schedule]] config tables (PLC-initiated messages, W596 3):
//
//   [[remote]]                 where a remote FINS node is (else: automatic generation,
//   network = 0                this node's IP with the last octet = node, same port)
//   node = 5
//   address = "127.0.1.5:9600" (IPv6 "[::1]:9600"; no port: 9600)
//   transport = "udp"          "tcp": finsd opens a FINS/TCP client connection to it
//                              (tcp_client.hpp; one of max_connections)
//   client_node = 0            tcp: our node on it, 0 = allocated by the server (default)
//
//   [[schedule]]               an instruction run every period
//   every = "1s"               "250ms", "2s", "1min" (10 ms at least)
//   instruction = "send"       send, recv or sendcmd
//   dest = "0.5.0"             NET.NODE.UNIT
//   local = "D100"             send/recv: local words
//   remote = "D200"            send/recv: remote words
//   count = 10                 send/recv: words 0-990 (default 1)
//   command = "0501"           sendcmd: hex MRC SRC parameters
//   timeout = 20               0.1 s, 0 = 2 s (default 0)
//   retries = 0                0-15
//   no_response = false
// At most 32 [[schedule]] entries (the W596 limit of instructions at once).
#pragma once

#include <string>
#include <string_view>

#include <toml++/toml.h>
#include <tl/expected.hpp>

#include "server/instructions/instruction_schedule.hpp"
#include "server/instructions/instruction_udp.hpp"

namespace fins::plc {
class IoMemory;
}

namespace fins::finsd {

struct Settings;

struct ScheduleEntry {
    std::string where;  // "file:line:column" of the entry
    server::ScheduledInstruction scheduled;
};

// `node` is the value of the top-level key "remote" / "schedule" at `key`.
tl::expected<void, std::string> load_remotes(const toml::key& key, const toml::node& node,
                                             std::string_view source, Settings& settings);
tl::expected<void, std::string> load_schedule(const toml::key& key, const toml::node& node,
                                              std::string_view source, Settings& settings);
// Each entry against the model (local words exist, ranges) and the FINS/TCP client
// connections against max_connections: the first problem, named.
tl::expected<void, std::string> check_schedule(const Settings& settings,
                                               const plc::IoMemory& memory);

}  // namespace fins::finsd
