// libFuzzer target: arbitrary bytes as a FINS request frame through the whole request
// handling path (dispatcher, execution conditions, handlers, I/O memory), on every route
// a frame can take. The frame arrives at CPU Unit A's unit on network 1 (node 10, the
// tests' server node), and A has
//   - routing tables: network 1 on unit 0, network 2 on unit 1 (A is 2.1), network 3
//     via 2.5; CPU Unit B is 2.5 (no tables of its own: 0502 when asked to relay);
//   - a Serial Gateway port at unit 80 (28 03/04/05) and a port whose Host Link slaves
//     are FINS network 5 (unit 81), both on a device that does not exist, so a request
//     that reaches one is answered 0205 (a later answer, through the reply path).
// The PLCs live across inputs so writes, modes and forced bits build up state as real
// ones would. Invariants checked: every answer, now or later, fits the 2,012-byte frame
// and is a response frame echoing the request's SID and command code.
#include <array>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>

#include "answer_check.hpp"
#include "every_route.hpp"
#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/routing/router.hpp"
#include "server/serial/serial_ports.hpp"
#include "transport/asio.hpp"

namespace {

using namespace fins;

// Answers that come later are checked against the request being handled.
class CheckedReplies final : public server::ReplyPath {
  public:
    CheckedReplies() = default;
    CheckedReplies(const CheckedReplies&) = delete;
    CheckedReplies& operator=(const CheckedReplies&) = delete;
    ~CheckedReplies() = default;
    server::Completion defer() override {
        return [this](Bytes answer) { fins_fuzz::check_answer(request, answer); };
    }
    Bytes request;
};

struct Routes {
    asio::io_context io;
    plc::Plc a;
    plc::Plc b;
    server::Router router;
    server::Dispatcher a1{a, {1, 10, 0}};
    server::Dispatcher a2{a, {2, 1, 0}};
    server::Dispatcher b2{b, {2, 5, 0}};
    server::SerialPorts ports;
    CheckedReplies replies;

    Routes() {
        spdlog::set_level(spdlog::level::off);
        const auto cpu_a = router.add_cpu(a, false);
        const auto cpu_b = router.add_cpu(b, false);
        const std::array<std::pair<std::size_t, server::Dispatcher*>, 3> ports_of{
            std::pair{router.add_port(cpu_a, 0, {1, 10, 0}), &a1},
            std::pair{router.add_port(cpu_a, 1, {2, 1, 0}), &a2},
            std::pair{router.add_port(cpu_b, 0, {2, 5, 0}), &b2}};
        for (const auto& [port, dispatcher] : ports_of) {
            dispatcher->attach(router, port);
            router.set_dispatcher(port, *dispatcher);
        }
        fins_fuzz::write_routing_tables(a);

        fins_fuzz::add_gateway_ports(io, ports);
        a1.attach_serial_ports(&ports);
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static Routes routes;
    static std::array<std::uint8_t, max_frame_size> out{};
    const Bytes request{data, size};
    routes.replies.request = request;
    server::RequestContext context{};
    context.reply_path = &routes.replies;
    const std::size_t n = routes.a1.handle(request, out, context);
    routes.io.poll();  // a gateway port's next request, if any
    if (n == 0) return 0;
    fins_fuzz::check_answer(request, Bytes{out.data(), n});
    return 0;
}
