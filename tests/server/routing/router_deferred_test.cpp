// An answer that comes later through a router (W342 5-1-3, README "Routing"): a
// Serial Gateway port's answer (28 04 to a node behind a router) crosses the router on
// its way back like an answer on the call stack: its GCT drops by one there too.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <pty.h>
#include <unistd.h>

#include <array>
#include <memory>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "fins/modbus.hpp"
#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/routing/router.hpp"
#include "server/serial/serial_ports.hpp"
#include "transport/asio.hpp"

namespace fins::server {
namespace {

using namespace std::chrono_literals;

class KeptReplies final : public ReplyPath {
  public:
    KeptReplies() = default;
    KeptReplies(const KeptReplies&) = delete;
    KeptReplies& operator=(const KeptReplies&) = delete;
    ~KeptReplies() = default;
    Completion defer() override {
        return [this](Bytes frame) { answers.emplace_back(frame.begin(), frame.end()); };
    }
    std::vector<std::vector<std::uint8_t>> answers;
};

std::vector<std::uint8_t> rtu(const std::vector<std::uint8_t>& pdu) {
    std::vector<std::uint8_t> out(pdu.size() + 2);
    ByteWriter w(out);
    modbus::write_rtu_frame(w, pdu);
    return out;
}

TEST(RouterDeferred, W342_5_1_3_GatewayAnswerThroughARouterHasItsGctDecrementedOnTheWayBack) {
    int master = -1;
    int slave = -1;
    char name[64] = {};
    ASSERT_EQ(::openpty(&master, &slave, name, nullptr, nullptr), 0);

    // CPU Unit A routes between networks 1 and 2; CPU Unit B (2.5) has a gateway port 80.
    asio::io_context io;
    plc::Plc a;
    plc::Plc b;
    Router router;
    const auto cpu_a = router.add_cpu(a, false);
    const auto cpu_b = router.add_cpu(b, false);
    const auto a1 = router.add_port(cpu_a, 0, {1, 1, 0});
    const auto a2 = router.add_port(cpu_a, 1, {2, 1, 0});
    const auto b2 = router.add_port(cpu_b, 0, {2, 5, 0});
    Dispatcher da1(a, {1, 1, 0});
    Dispatcher da2(a, {2, 1, 0});
    Dispatcher db2(b, {2, 5, 0});
    for (const auto& [port, d] : {std::pair{a1, &da1}, std::pair{a2, &da2}, std::pair{b2, &db2}}) {
        d->attach(router, port);
        router.set_dispatcher(port, *d);
    }
    plc::RoutingTables tables;
    tables.local[0] = {1, 0};
    tables.local[1] = {2, 1};
    tables.local_count = 2;
    plc::encode_routing_tables(tables, a.parameters().words(plc::routing_table_area));
    GatewayPortConfig config;
    config.name = "scu0.1";
    config.unit_address = 0x80;
    config.line.device = name;
    config.line.data_bits = 8;
    config.timeout = 2s;
    SerialPorts ports;
    auto port = std::make_shared<SerialGatewayPort>(io, config);
    ASSERT_FALSE(port->open());
    ports.add(port);
    db2.attach_serial_ports(&ports);

    // 28 04 read holding register 0 of slave 1, to 2.5.80 from 1.20, GCT 02.
    const std::vector<std::uint8_t> request{0x80, 0x00, 0x02, 0x02, 0x05, 0x80, 0x01, 0x14, 0x00,
                                            0x33, 0x28, 0x04, 0x01, 0x03, 0x00, 0x00, 0x00, 0x01};
    KeptReplies replies;
    RequestContext context{};
    context.reply_path = &replies;
    std::array<std::uint8_t, max_frame_size> out{};
    EXPECT_EQ(da1.handle(request, out, context), 0U);  // answered later

    ::fcntl(master, F_SETFL, O_NONBLOCK);
    bool sent = false;
    for (int i = 0; i < 400 && replies.answers.empty(); ++i) {
        io.run_for(5ms);
        std::array<std::uint8_t, 64> buf{};
        if (!sent && ::read(master, buf.data(), buf.size()) > 0) {
            const auto answer = rtu({0x01, 0x03, 0x02, 0x12, 0x34});
            ASSERT_EQ(::write(master, answer.data(), answer.size()),
                      static_cast<ssize_t>(answer.size()));
            sent = true;
        }
    }
    ASSERT_EQ(replies.answers.size(), 1U);
    const auto& answer = replies.answers.front();
    ASSERT_GE(answer.size(), 14U);
    EXPECT_EQ(answer[12], 0x00);  // 0000
    EXPECT_EQ(answer[13], 0x00);
    EXPECT_EQ(answer[6], 2);  // from 2.5.80
    EXPECT_EQ(answer[7], 5);
    // 02 on the way out becomes 01 at B; the answer starts there and crosses A: 00.
    EXPECT_EQ(answer[2], 0x00);

    port->close();
    io.run_for(20ms);
    ::close(master);
    ::close(slave);
}

}  // namespace
}  // namespace fins::server
