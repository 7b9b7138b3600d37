// The unit faults of a running scenario that the network side applies (issue 19): what
// the Dispatcher and the accept loop consult for each request and connection. Implemented
// by ScenarioRunner (scenario_runner.hpp); null when the CPU Unit runs no scenario, and
// then nothing changes on the request path.
//
//   offline   no answer to any request (datagrams ignored), new FINS/TCP connections
//             closed at once: a unit switched off
//   drop      a fraction of requests get no answer
//   end_code  memory area commands (01 01-01 05) naming an address in a faulted area
//             (any element of 01 04, the source or destination of 01 05, word or bit
//             codes) answer that area's end code; several areas may be faulted at once
//   latency   answers leave that much later, through the session's deferred-answer path
//             (ReplyPath), so no other node or request waits for them
#pragma once

#include <chrono>
#include <cstdint>

#include "fins/byte_io.hpp"
#include "fins/memory_area.hpp"
#include "server/dispatch/dispatcher.hpp"

namespace fins::server {

class FaultHook {
  public:
    virtual ~FaultHook() = default;
    // The unit is switched off: no answers, no new connections.
    [[nodiscard]] virtual bool offline() const noexcept = 0;
    // True when this request gets no answer (offline, or drawn by the drop fraction).
    virtual bool silent() noexcept = 0;
    // The end code a memory area command naming `address` answers (0: none).
    [[nodiscard]] virtual std::uint16_t area_end_code(
        const MemoryAddress& address) const noexcept = 0;
    // How long answers wait (0: none).
    [[nodiscard]] virtual std::chrono::milliseconds latency() const noexcept = 0;
    // Sends `response` through `completion` once latency() has passed.
    virtual void send_later(Bytes response, Completion completion) = 0;
};

}  // namespace fins::server
