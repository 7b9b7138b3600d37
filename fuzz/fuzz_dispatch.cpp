// libFuzzer target: arbitrary bytes as a FINS request frame through the whole request
// handling path (dispatcher, execution conditions, handlers, I/O memory). The PLC lives
// across inputs so writes, modes and forced bits build up state as a real one would.
// Invariants checked: the response fits the 2,012-byte frame and, when there is one, it
// is a response frame echoing the request's SID and command code.
#include <array>
#include <cstdint>
#include <cstdlib>

#include "answer_check.hpp"
#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "server/dispatch/dispatcher.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static fins::plc::Plc plc;
    static fins::server::Dispatcher dispatcher{plc, {0, 1, 0}};
    static std::array<std::uint8_t, fins::max_frame_size> out{};
    const fins::Bytes request{data, size};
    const fins::server::RequestContext context{};
    const std::size_t n = dispatcher.handle(request, out, context);
    if (n == 0) return 0;
    fins_fuzz::check_answer(request, fins::Bytes{out.data(), n});
    return 0;
}
