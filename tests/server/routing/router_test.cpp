// Router without sockets (server/routing/router.hpp): "is it for me" per port, W596 A-1's
// network for DNA 00, and the exact bytes of a relay-error answer.
#include "server/routing/router.hpp"

#include <array>
#include <vector>

#include <gtest/gtest.h>

#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/dispatch/dispatcher.hpp"

namespace fins::server {
namespace {

TEST(Router, LocalAddressIsAnyUnitOfTheCpuUnit) {
    plc::Plc plc;
    Router r;
    const auto cpu = r.add_cpu(plc, false);
    const auto p1 = r.add_port(cpu, 0, {1, 1, 0});
    r.add_port(cpu, 1, {2, 7, 0});
    // DNA 00 or the arrival network: this port (DA1 is checked by the dispatcher).
    EXPECT_EQ(r.local_address(p1, {0, 9, 0}), (NodeAddress{1, 1, 0}));
    EXPECT_EQ(r.local_address(p1, {1, 9, 0}), (NodeAddress{1, 1, 0}));
    // The other unit's network: DA1 00 or its node is this CPU Unit, others are not.
    EXPECT_EQ(r.local_address(p1, {2, 7, 0}), (NodeAddress{2, 7, 0}));
    EXPECT_EQ(r.local_address(p1, {2, 0, 0}), (NodeAddress{2, 7, 0}));
    EXPECT_FALSE(r.local_address(p1, {2, 8, 0}));
    EXPECT_FALSE(r.local_address(p1, {3, 7, 0}));
    EXPECT_EQ(r.find_port(2, 7), std::optional<std::size_t>{1});
    EXPECT_FALSE(r.find_port(2, 8));
}

TEST(Router, W596_A_1_Network0IsTheSmallestUnitNumberOnCsCjAndTheBuiltInPortOnNx) {
    plc::Plc cj;
    plc::Plc nx;
    Router r;
    const auto a = r.add_cpu(cj, false);
    r.add_port(a, 3, {5, 1, 0});
    r.add_port(a, 1, {6, 1, 0});
    r.add_port(a, 2, {7, 1, 0});
    EXPECT_EQ(r.network_for_local(a), 6);
    const auto b = r.add_cpu(nx, true);
    r.add_port(b, 2, {8, 2, 0});
    r.add_port(b, 0, {9, 2, 0});
    EXPECT_EQ(r.network_for_local(b), 8);
}

TEST(Router, W342_5_1_3_RelayErrorAnswerBytes) {
    plc::Plc plc;
    Router r;
    const auto cpu = r.add_cpu(plc, false);
    const auto port = r.add_port(cpu, 0, {1, 1, 0});
    Dispatcher d(plc, {1, 1, 0});
    d.attach(r, port);
    r.set_dispatcher(port, d);
    plc::RoutingTables t;
    t.local[0] = {1, 0};
    t.local_count = 1;
    plc::encode_routing_tables(t, plc.parameters().words(plc::routing_table_area));
    // 01 01 to 4.5.0 from 0.77.0, SID 42, GCT 02.
    const std::vector<std::uint8_t> request{0x80, 0x00, 0x02, 0x04, 0x05, 0x00, 0x00, 77,   0x00,
                                            0x42, 0x01, 0x01, 0x82, 0x00, 0x00, 0x00, 0x00, 0x01};
    std::array<std::uint8_t, max_frame_size> out{};
    const auto n = d.handle(request, out, {});
    // Response header (source = the command's destination, GCT 02), 01 01, end code
    // 8501 (0501 + relay bit), relay word: network 1, node 1.
    const std::vector<std::uint8_t> expected{0xC0, 0x00, 0x02, 0x00, 77,   0x00, 0x04, 0x05,
                                             0x00, 0x42, 0x01, 0x01, 0x85, 0x01, 0x01, 0x01};
    EXPECT_EQ(std::vector<std::uint8_t>(out.begin(), out.begin() + static_cast<long>(n)), expected);
    // No answer is asked for (ICF bit 0): none, not even a relay error.
    auto quiet = request;
    quiet[0] = 0x81;
    EXPECT_EQ(d.handle(quiet, out, {}), 0u);
    // Both were taken by the router and refused with 0501 (finsd's page shows these).
    using Counts = std::vector<std::pair<std::uint16_t, std::uint64_t>>;
    EXPECT_EQ(r.relay_counts(plc), (Counts{{0x0000, 0}, {0x0501, 2}}));
    plc::Plc other;
    EXPECT_TRUE(r.relay_counts(other).empty());
}

TEST(Router, W596_1_2_AnOversizedFrameForAnotherNetworkAnswers1001WithTheRelayFlag) {
    plc::Plc plc;
    Router r;
    const auto cpu = r.add_cpu(plc, false);
    const auto port = r.add_port(cpu, 0, {1, 1, 0});
    Dispatcher d(plc, {1, 1, 0});
    d.attach(r, port);
    r.set_dispatcher(port, d);
    std::vector<std::uint8_t> request(max_frame_size + 1, 0);
    const std::vector<std::uint8_t> head{0x80, 0x00, 0x02, 0x04, 0x05, 0x00,
                                         0x00, 77,   0x00, 0x42, 0x01, 0x02};
    std::copy(head.begin(), head.end(), request.begin());
    std::array<std::uint8_t, max_frame_size> out{};
    const auto n = d.handle(request, out, {});
    ASSERT_EQ(n, 16u);
    EXPECT_EQ(out[12], 0x90);
    EXPECT_EQ(out[13], 0x01);
}

}  // namespace
}  // namespace fins::server
