// The Host Link FINS relay (W342 5-1-1, handlers/host_link_relay.cpp) on an openpty()
// pair, the test playing the Host Link slave: an answer with another SID than the
// request's is not its answer (dropped, counted, the request keeps waiting), and the
// answer passed back crosses the gateway: the slave's GCT less one.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <pty.h>
#include <unistd.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "fins/host_link.hpp"
#include "plc/plc.hpp"
#include "server/dispatch/dispatcher.hpp"
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

constexpr std::uint8_t port_unit = 0x84;  // SCU 1 port 1, also the slaves' network
constexpr std::uint8_t host_link_unit = 3;
constexpr std::uint8_t request_sid = 0x42;

class HostLinkRelay : public ::testing::Test {
  protected:
    void SetUp() override {
        char name[64] = {};
        ASSERT_EQ(::openpty(&master_, &slave_, name, nullptr, nullptr), 0);
        ::fcntl(master_, F_SETFL, O_NONBLOCK);
        GatewayPortConfig c;
        c.name = "scu1.1";
        c.unit_address = port_unit;
        c.line.device = name;
        c.line.data_bits = 8;
        c.timeout = 2s;
        port_ = std::make_shared<SerialGatewayPort>(io_, c);
        ASSERT_FALSE(port_->open());
        ports_.add(port_);
        dispatcher_.attach_serial_ports(&ports_);
        context_.reply_path = &replies_;
    }
    void TearDown() override {
        port_->close();
        io_.run_for(20ms);
        ::close(master_);
        ::close(slave_);
    }
    // 01 01 read of one word, to the slave's CPU Unit, GCT 02.
    void send_read() {
        const std::vector<std::uint8_t> request{0x80, 0x00, 0x02, port_unit, host_link_unit + 1,
                                                0x00, 0x01, 0x14, 0x00,      request_sid,
                                                0x01, 0x01, 0x82, 0x00,      0x64,
                                                0x00, 0x00, 0x01};
        std::array<std::uint8_t, max_frame_size> out{};
        ASSERT_EQ(dispatcher_.handle(request, out, context_), 0U);  // answered later
    }
    // Runs the port until the Host Link command is on the line.
    std::string line_read() {
        std::string got;
        for (int i = 0; i < 200 && got.find('\r') == std::string::npos; ++i) {
            io_.run_for(5ms);
            std::array<char, 512> buf{};
            const auto n = ::read(master_, buf.data(), buf.size());
            if (n > 0) got.append(buf.data(), static_cast<std::size_t>(n));
        }
        return got;
    }
    // The slave's answer: 01 01 0000 1234 from its CPU Unit, with `sid` and GCT `gct`.
    void answer(std::uint8_t sid, std::uint8_t gct) {
        const std::vector<std::uint8_t> fins{0xC0, 0x00, gct,  0x01, 0x14, 0x00, 0x00, 0x00,
                                             0x00, sid,  0x01, 0x01, 0x00, 0x00, 0x12, 0x34};
        std::array<std::uint8_t, host_link_max_response_chars> text{};
        const auto n = encode_host_link_response(host_link_unit, HostLinkForm::network, fins, text);
        ASSERT_TRUE(n.has_value());
        ASSERT_EQ(::write(master_, text.data(), *n), static_cast<ssize_t>(*n));
    }
    void run_until_answered() {
        for (int i = 0; i < 200 && replies_.answers.empty(); ++i)
            io_.run_for(5ms);
    }

    asio::io_context io_;
    int master_ = -1;
    int slave_ = -1;
    std::shared_ptr<SerialGatewayPort> port_;
    SerialPorts ports_;
    plc::Plc plc_;
    Dispatcher dispatcher_{plc_, {1, 10, 0}};
    KeptReplies replies_;
    RequestContext context_{};
};

// W342 5-1-1 / frames-serial-files.md 3 ("SID is used as a counter when resending"): a
// FINS answer is matched to its request by SID; an answer on the line with another SID
// (a late one, to an earlier request) is not this request's answer.
TEST_F(HostLinkRelay, W342_5_1_1_AnAnswerWithAnotherSidIsDroppedAndTheRequestKeepsWaiting) {
    send_read();
    const auto command = line_read();
    ASSERT_EQ(command.rfind("@03FA", 0), 0U) << command;
    answer(request_sid - 1, 0x01);
    for (int i = 0; i < 20; ++i)
        io_.run_for(5ms);
    EXPECT_TRUE(replies_.answers.empty()) << "an answer with another SID was taken";
    EXPECT_EQ(port_->counters().foreign_answers, 1U);
    answer(request_sid, 0x01);
    run_until_answered();
    ASSERT_EQ(replies_.answers.size(), 1U);
    const auto& r = replies_.answers.front();
    ASSERT_EQ(r.size(), 16U);
    EXPECT_EQ(r[9], request_sid);
    EXPECT_EQ(r[12], 0x00);  // 0000
    EXPECT_EQ(r[13], 0x00);
    EXPECT_EQ(r[14], 0x12);
    EXPECT_EQ(r[15], 0x34);
}

// W342 5-1-1 note: the gateway is a relay. The command left with GCT 02 - 1 = 01; the
// slave answers with 01; the answer crosses the gateway back as it would a router
// (README "Routing"): 00. Before, the request's own 02 was echoed.
TEST_F(HostLinkRelay, W342_5_1_1_TheRelayedAnswerHasItsGctDecrementedAtTheGateway) {
    send_read();
    ASSERT_FALSE(line_read().empty());
    answer(request_sid, 0x01);
    run_until_answered();
    ASSERT_EQ(replies_.answers.size(), 1U);
    const auto& r = replies_.answers.front();
    ASSERT_GE(r.size(), 10U);
    EXPECT_EQ(r[2], 0x00);
    EXPECT_EQ(r[6], port_unit);  // from the address the client asked
    EXPECT_EQ(r[7], host_link_unit + 1);
}

}  // namespace
}  // namespace fins::server
