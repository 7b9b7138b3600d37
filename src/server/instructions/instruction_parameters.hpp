// The parameters of Send, Rcv and SendCmd (W596 3): the request a node's program (or
// finsd's config and control socket) gives, its limits, and the checks and parsers
// that turn text and numbers into one. The engine that runs a request is
// network_instructions.hpp; this file has no I/O.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fins/address.hpp"
#include "fins/frame.hpp"
#include "plc/io_memory.hpp"

namespace fins::server {

inline constexpr std::size_t max_instructions = 32;  // W596 3: Send, Rcv, SendCmd at once
// Words per Send/Rcv: W596 says "depends on the network type"; 990 is the CS/CJ
// SEND(090)/RECV(098) limit over Ethernet, and fits one 01 02 / 01 01 frame.
inline constexpr std::uint16_t max_instruction_words = 990;
inline constexpr std::uint8_t max_instruction_retries = 15;
// SendCmd: MRC SRC and up to 2,000 parameter bytes.
inline constexpr std::size_t max_instruction_command = max_frame_size - header_size;
inline constexpr std::uint16_t default_instruction_timeout = 20;  // 0.1 s units (W596)

// ErrorID values.
inline constexpr std::uint16_t instruction_done = 0x0000;
inline constexpr std::uint16_t instruction_parameter_error = 0x0400;
inline constexpr std::uint16_t instruction_communications_error = 0x0800;

enum class InstructionKind : std::uint8_t { send, recv, sendcmd };

struct InstructionOptions {
    bool no_response = false;   // Option.isNonResp
    std::uint16_t timeout = 0;  // Option.TimeOut, 0.1 s; 0 = 2.0 s
    unsigned retries = 0;       // Option.Retry, 0-15
};

struct InstructionRequest {
    InstructionKind kind = InstructionKind::send;
    NodeAddress destination;
    Address local;   // Send: the words sent; Rcv: where the answer is stored
    Address remote;  // Send: DstArea/DstCh; Rcv: SrcArea/SrcCh
    std::uint16_t count = 0;
    std::vector<std::uint8_t> command;  // SendCmd: MRC SRC parameters
    InstructionOptions options;
};

// The request's parameters against W596's ranges and the local model: empty when it
// may run, else why not (ErrorID 0400). Used by start() and by the config loader.
std::optional<std::string> check_instruction(const InstructionRequest& request,
                                             const plc::IoMemory& memory);
// Milliseconds of Option.TimeOut (0 = 2.0 s).
std::chrono::milliseconds instruction_timeout(std::uint16_t timeout) noexcept;
// "send" / "recv" / "sendcmd" (also "rcv", "cmnd").
std::optional<InstructionKind> parse_instruction_kind(std::string_view text) noexcept;
const char* instruction_kind_name(InstructionKind kind) noexcept;
// "NET.NODE.UNIT" (unit decimal or hex with 0x) or "NET.NODE" (unit 0).
std::optional<NodeAddress> parse_destination(std::string_view text) noexcept;

// The request's local words as a located range (Send reads them, Rcv writes them).
Result<plc::ElementRange> locate_instruction_words(const plc::IoMemory& memory,
                                                   const InstructionRequest& request);

}  // namespace fins::server
