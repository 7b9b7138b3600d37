// Where a node's Send/Rcv/SendCmd frames go (instruction_udp.hpp): [[remote]] entries
// first, else W596 2-3 automatic generation (own IP, last octet = node, own port).
#include "server/instructions/instruction_udp.hpp"

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>

#include "plc/plc.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/sessions/udp_session.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using server::RemoteNode;
using server::UdpInstructionTransport;

class InstructionUdp : public ::testing::Test {
  protected:
    InstructionUdp() : dispatcher_(plc_, self_) {
        asio::ip::udp::socket s(io_);
        s.open(asio::ip::udp::v4());
        s.bind({asio::ip::make_address("127.0.0.1"), 0});
        udp_ = std::make_shared<server::UdpSession>(std::move(s), dispatcher_);
    }
    std::string endpoint(const UdpInstructionTransport& t, NodeAddress to) {
        const auto e = t.resolve(to);
        return e ? e->address().to_string() + ":" + std::to_string(e->port()) : "none";
    }

    asio::io_context io_;
    plc::Plc plc_;
    NodeAddress self_{0, 1, 0};
    server::Dispatcher dispatcher_;
    std::shared_ptr<server::UdpSession> udp_;
};

TEST_F(InstructionUdp, W596_2_3_AutomaticGenerationUsesOwnPrefixAndOwnPort) {
    UdpInstructionTransport t(udp_, asio::ip::make_address("127.0.0.1"), self_, {});
    const auto port = std::to_string(udp_->local_port());
    EXPECT_EQ(endpoint(t, {0, 5, 0}), "127.0.0.5:" + port);
    EXPECT_EQ(endpoint(t, {0, 0, 0}), "127.0.0.1:" + port);  // node 00: this PLC
    EXPECT_EQ(endpoint(t, {3, 5, 0}), "none");               // another network: 0501
}

TEST_F(InstructionUdp, RemoteEntriesComeFirstAndNameOtherNetworks) {
    UdpInstructionTransport t(udp_, asio::ip::make_address("127.0.0.1"), self_,
                              {RemoteNode{0, 5, "127.0.1.5", 9700}, RemoteNode{3, 9, "::1", 9601}});
    EXPECT_EQ(endpoint(t, {0, 5, 0}), "127.0.1.5:9700");
    EXPECT_EQ(endpoint(t, {3, 9, 0}), "::1:9601");
    EXPECT_EQ(endpoint(t, {3, 5, 0}), "none");
}

TEST_F(InstructionUdp, AWildcardBindHasNoPrefix) {
    UdpInstructionTransport t(udp_, asio::ip::make_address("0.0.0.0"), self_, {});
    EXPECT_EQ(endpoint(t, {0, 5, 0}), "none");
    server::InstructionRoute route;
    EXPECT_EQ(t.send_frame({0, 5, 0}, Bytes{}, route),
              server::InstructionTransport::Sent::no_route);
}

TEST_F(InstructionUdp, WithoutUdpNothingIsSent) {
    UdpInstructionTransport t(nullptr, asio::ip::make_address("127.0.0.1"), self_, {});
    const std::uint8_t frame[12]{0x80};
    server::InstructionRoute route;
    EXPECT_EQ(t.send_frame({0, 5, 0}, Bytes{frame, sizeof frame}, route),
              server::InstructionTransport::Sent::no_port);
}

// Issue 18 item 6: the way a frame went is the node address table's entry, the only
// address and port its answer is accepted from.
TEST_F(InstructionUdp, Issue18_TheRouteIsTheAddressAndPortTheFrameWentTo) {
    UdpInstructionTransport t(udp_, asio::ip::make_address("127.0.0.1"), self_,
                              {RemoteNode{0, 5, "127.0.0.1", 9700}});
    const std::uint8_t frame[12]{0x80};
    server::InstructionRoute route;
    ASSERT_EQ(t.send_frame({0, 5, 0}, Bytes{frame, sizeof frame}, route),
              server::InstructionTransport::Sent::ok);
    EXPECT_EQ(route.connection, nullptr);
    EXPECT_EQ(route.udp.address().to_string() + ":" + std::to_string(route.udp.port()),
              "127.0.0.1:9700");
}

}  // namespace
}  // namespace fins::test
