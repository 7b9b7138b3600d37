// libFuzzer target: arbitrary bytes as a frame arriving at router-a of the three-network
// plant of examples/three-networks.toml, without sockets: the Router forwards through
// router-b to line-3 by the 8013 routing tables, which the input may itself rewrite
// (02 02 / 02 03 to 1.1). The plant lives across inputs. Invariants: the answer fits the
// 2,012-byte frame and, when there is one, is a response frame echoing the SID and
// command code (a relay error included).
#include <array>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include "answer_check.hpp"
#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/routing/router.hpp"

namespace {

struct Plant {
    fins::plc::Plc a, b, line;
    fins::server::Router router;
    std::array<std::unique_ptr<fins::server::Dispatcher>, 5> dispatchers;

    Plant() {
        using fins::plc::LocalNetwork;
        using fins::plc::RelayNetwork;
        const auto ca = router.add_cpu(a, false);
        const auto cb = router.add_cpu(b, false);
        const auto cl = router.add_cpu(line, false);
        const std::array<std::pair<std::size_t, fins::NodeAddress>, 5> ports{
            {{ca, {1, 1, 0}}, {ca, {2, 1, 0}}, {cb, {2, 2, 0}}, {cb, {3, 2, 0}}, {cl, {3, 5, 0}}}};
        const std::array<fins::plc::Plc*, 3> plcs{&a, &b, &line};
        std::array<std::uint8_t, 3> unit{};
        for (std::size_t i = 0; i < ports.size(); ++i) {
            const auto [cpu, address] = ports[i];
            const auto p = router.add_port(cpu, unit[cpu]++, address);
            dispatchers[i] = std::make_unique<fins::server::Dispatcher>(*plcs[cpu], address);
            dispatchers[i]->attach(router, p);
            router.set_dispatcher(p, *dispatchers[i]);
        }
        fins::plc::RoutingTables ta;
        ta.local[0] = LocalNetwork{1, 0};
        ta.local[1] = LocalNetwork{2, 1};
        ta.local_count = 2;
        ta.relay[0] = RelayNetwork{3, 2, 2};
        ta.relay_count = 1;
        fins::plc::encode_routing_tables(ta, a.parameters().words(fins::plc::routing_table_area));
        fins::plc::RoutingTables tb;
        tb.local[0] = LocalNetwork{2, 0};
        tb.local[1] = LocalNetwork{3, 1};
        tb.local_count = 2;
        tb.relay[0] = RelayNetwork{1, 2, 1};
        tb.relay_count = 1;
        fins::plc::encode_routing_tables(tb, b.parameters().words(fins::plc::routing_table_area));
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static Plant plant;
    static std::array<std::uint8_t, fins::max_frame_size> out{};
    const fins::Bytes request{data, size};
    const std::size_t n = plant.dispatchers[0]->handle(request, out, {});
    if (n == 0) return 0;
    fins_fuzz::check_answer(request, fins::Bytes{out.data(), n});
    return 0;
}
