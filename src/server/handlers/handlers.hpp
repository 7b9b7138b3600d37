// Private to the server: the command handlers and their registry.
//
// A handler receives the decoded command and the PLC, writes its response data (the
// bytes after the end code) through a ByteWriter over the response buffer, and returns
// the end code. On any end code other than 0000 the dispatcher discards the data and
// answers the end code alone, unless the handler set keep_data. Handlers never see the frame header
// checks or the execution conditions: the dispatcher has done those (W342 5-1-2) before calling.
//
// One file per command group of W342 section 5: memory_area.cpp = 01 xx, ...
#pragma once

#include <span>
#include <system_error>

#include "fins/byte_io.hpp"
#include "fins/command_table.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "server/dispatch/dispatcher.hpp"

namespace fins::plc {
class Plc;
enum class OperatingMode : std::uint8_t;
}  // namespace fins::plc

namespace fins::server {
class SerialGatewayPort;
}

namespace fins::server::handlers {

struct HandlerContext {
    plc::Plc& plc;
    const Header& header;  // the request's header (source address for access rights ...)
    const RequestContext& request;
    // Set by a handler whose data goes out with a non-zero end code: 02 01 past the
    // area end (data + 1104), 21 02 (records + 1104), 0C 01 (3001 + the holder).
    bool keep_data = false;
    // Set by a handler whose variant is a FINS write although its command's row is not
    // (09 20 MESSAGE CLEAR): the dispatcher logs it in the write access log (5-3-30).
    bool write = false;
    // The Serial Gateway ports (28 xx handlers) and this node's address.
    SerialPorts* serial = nullptr;
    NodeAddress self{};
    // Set by a handler that handed the request on (a serial port): no answer now, its
    // completion sends it later.
    bool deferred = false;
};

using HandlerFunction = EndCode (*)(HandlerContext& context, Bytes parameters, ByteWriter& out);

struct HandlerEntry {
    CommandCode code;
    HandlerFunction function;
};

// Every command this server implements; each also has a row in fins::command_table().
// Built from the group tables below, ascending by command code.
std::span<const HandlerEntry> handler_table() noexcept;
const HandlerEntry* find_handler(CommandCode code) noexcept;

// One table per command group of W342 section 5, each defined in its group's file.
std::span<const HandlerEntry> memory_area_handlers() noexcept;     // 01 xx  memory_area.cpp
std::span<const HandlerEntry> parameter_area_handlers() noexcept;  // 02 xx  parameter_area.cpp
std::span<const HandlerEntry> program_area_handlers() noexcept;    // 03 xx  program_area.cpp
std::span<const HandlerEntry> operating_mode_handlers() noexcept;  // 04 xx  operating_mode.cpp
std::span<const HandlerEntry> configuration_handlers() noexcept;   // 05 xx  configuration.cpp
std::span<const HandlerEntry> status_handlers() noexcept;          // 06 xx  status.cpp
std::span<const HandlerEntry> cpu_status_handlers() noexcept;      // 06 01  cpu_status.cpp
std::span<const HandlerEntry> clock_handlers() noexcept;           // 07 xx  clock.cpp
std::span<const HandlerEntry> message_handlers() noexcept;         // 09 20  messages.cpp
std::span<const HandlerEntry> access_right_handlers() noexcept;    // 0C xx  access_right.cpp
std::span<const HandlerEntry> error_log_handlers() noexcept;       // 21 xx  error_log.cpp
std::span<const HandlerEntry> forced_handlers() noexcept;          // 23 xx  forced.cpp
std::span<const HandlerEntry> file_memory_handlers() noexcept;     // 22 xx  file_memory.cpp
                                                                   //  (0A-0C file_transfer.cpp)
std::span<const HandlerEntry> serial_gateway_handlers() noexcept;  // 28 xx  serial_gateway.cpp

// Host Link FINS conversion (W342 5-1-1, host_link_relay.cpp): sends the whole request
// frame on `port` as Host Link FINS and answers later; returns the length of an answer
// written to `out` now (an error end code), or 0 (deferred, or no answer wanted).
std::size_t relay_to_host_link(SerialGatewayPort& port, Bytes request, const Header& header,
                               const NodeAddress& self, MutableBytes out,
                               const RequestContext& context);

// The execution conditions of W342 5-1-2, checked in this order: operating mode
// (RUN 2206, MONITOR 2205, PROGRAM 2203), network write protection (2102, only for
// requests that came over a network link), access right held by another node (3001),
// UM read protection (2002), DIP switch UM write protection (2101).
EndCode check_execution_conditions(const ExecutionConditions& conditions, const plc::Plc& plc,
                                   const NodeAddress& source, Link link) noexcept;

// An operation only PROGRAM mode allows (file -> parameter or program area, I/O table
// write and clear, error log clear): its end code in `mode`, the mode that refused it
// (W342 5-1-3: 2206 RUN, 2205 MONITOR), 0000 in PROGRAM.
EndCode program_mode_only(plc::OperatingMode mode) noexcept;

// FINS end codes pass through; any other error (not expected from a decoder) is 1004.
EndCode to_end_code(const std::error_code& error) noexcept;

// Decodes C's parameters (1001/1002/... from the codec) and runs its handler, an
// `execute(HandlerContext&, const C&, ByteWriter&)` overload declared in this namespace.
template <class C>
EndCode handle(HandlerContext& context, Bytes parameters, ByteWriter& out) {
    const auto command = C::decode(parameters);
    if (!command) return to_end_code(command.error());
    return execute(context, *command, out);
}

template <class C>
constexpr HandlerEntry entry() noexcept {
    return HandlerEntry{C::code, &handle<C>};
}

// 01 xx I/O memory area access (memory_area.cpp, W342 5-3-2 .. 5-3-6).
EndCode execute(HandlerContext& context, const MemoryAreaRead& command, ByteWriter& out) noexcept;
EndCode execute(HandlerContext& context, const MemoryAreaWrite& command, ByteWriter& out) noexcept;
EndCode execute(HandlerContext& context, const MemoryAreaFill& command, ByteWriter& out) noexcept;
EndCode execute(HandlerContext& context, const MultipleMemoryAreaRead& command,
                ByteWriter& out) noexcept;
EndCode execute(HandlerContext& context, const MemoryAreaTransfer& command, ByteWriter& out);

}  // namespace fins::server::handlers
