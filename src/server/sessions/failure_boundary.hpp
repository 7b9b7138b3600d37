// The failure boundary of finsd's request paths (issue 25): nothing a request does may
// let an exception reach io_context::run, which would end every session of the process.
// Each FINS request (UDP datagram, FINS/TCP frame, a FINS/TCP client connection's
// command, a Host Link frame) and each control request (the Unix socket and
// POST /api/control, control_dispatch.hpp) runs inside one: an exception there
//   - is counted (fins_request_failures_total, fins_control_failures_total in /metrics),
//   - is logged at most once per log_summary_interval per channel (with the count since
//     the last line; each one at debug level),
//   - answers the request: a FINS request with end code 0301 "communications controller
//     error" (W342 5-1-3: an error in the unit that serves FINS) when its header asks
//     for an answer, a control request with {"error":"internal error: ..."},
// and the session goes on with its next request.
#pragma once

#include <exception>
#include <string>
#include <string_view>

#include "fins/byte_io.hpp"
#include "server/dispatch/dispatcher.hpp"

namespace fins::server {

enum class FailureChannel : std::uint8_t { fins, control };

// What `e` was, for the log and the control answer: "std::bad_alloc", the what() text of
// any other std::exception, or "an exception of no std type".
std::string describe_exception(const std::exception_ptr& e);

// Counts one failure of `channel` and writes its rate-limited log line. Never throws.
void note_failure(FailureChannel channel, std::string_view where, std::string_view what) noexcept;

// dispatcher.handle(request, out, context) inside the boundary. On an exception: the
// 0301 answer's length (written to `out`), or 0 when the request wants none (no-response
// ICF bit, a response frame, shorter than a header and command code).
std::size_t handle_guarded(Dispatcher& dispatcher, Bytes request, MutableBytes out,
                           const RequestContext& context) noexcept;

// An answer to one of this node's own instructions handed to the instruction engine
// (a session's response hook) inside the boundary: hook()'s result, or true (taken, so
// it is not dispatched as well) when it throws, counted and logged like a request.
template <class Hook>
bool take_response_guarded(Hook&& hook) noexcept {
    try {
        return hook();
    } catch (...) {
        std::string what = "an exception";
        try {
            what = describe_exception(std::current_exception());
        } catch (...) {
            // No memory for the text.
        }
        note_failure(FailureChannel::fins, "an answer to an instruction", what);
        return true;
    }
}

// Test seam: when set, called with each request inside the boundary before the
// dispatcher, so a test can make a request throw what a handler could (std::bad_alloc,
// nlohmann::json's exceptions, std::out_of_range). Null (the default): nothing.
using RequestFault = void (*)(Bytes request);
void set_request_fault_for_tests(RequestFault fault) noexcept;

}  // namespace fins::server
