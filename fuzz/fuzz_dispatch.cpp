// libFuzzer target: arbitrary bytes as a FINS request frame through the whole request
// handling path (dispatcher, execution conditions, handlers, I/O memory). The PLC lives
// across inputs so writes, modes and forced bits build up state as a real one would.
// Invariants checked: the response fits the 2,012-byte frame and, when there is one, it
// is a response frame echoing the request's SID and command code.
#include <array>
#include <cstdint>
#include <cstdlib>

#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "server/dispatcher.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static fins::plc::Plc plc;
    static fins::server::Dispatcher dispatcher{plc, {0, 1, 0}};
    static std::array<std::uint8_t, fins::max_frame_size> out{};
    const fins::Bytes request{data, size};
    const fins::server::RequestContext context{};
    const std::size_t n = dispatcher.handle(request, out, context);
    if (n == 0) return 0;
    if (n > fins::max_frame_size) std::abort();
    auto response = fins::decode_response(fins::Bytes{out.data(), n});
    auto parsed = fins::decode_request(request);
    if (!response || !parsed) std::abort();
    if (response->header.service_id != parsed->header.service_id) std::abort();
    if (!(response->command == parsed->command)) std::abort();
    return 0;
}
