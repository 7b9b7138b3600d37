// PlcPoller in-process on one io_context with its fins::Client (the one request engine),
// against a UDP responder on 127.0.0.1 that records every request frame: what the
// bridge puts on the wire for the `dest` it is given.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>

#include "bridge/bridge_test_support.hpp"
#include "bridge/poll/poller.hpp"

namespace fins::bridge {
namespace {

using namespace std::chrono_literals;
namespace net = boost::asio;

// Answers every 01 01 request with one word, 42, from the node the request was sent to.
class RecordingResponder {
  public:
    explicit RecordingResponder(net::io_context& io)
        : socket_(io, net::ip::udp::endpoint(net::ip::make_address("127.0.0.1"), 0)) {
        receive();
    }
    std::uint16_t port() const { return socket_.local_endpoint().port(); }
    const std::vector<std::vector<std::uint8_t>>& requests() const { return requests_; }

  private:
    void receive() {
        socket_.async_receive_from(net::buffer(rx_), peer_,
                                   [this](boost::system::error_code ec, std::size_t n) {
                                       if (ec) return;
                                       if (n >= 12) answer(n);
                                       receive();
                                   });
    }
    void answer(std::size_t n) {
        std::vector<std::uint8_t> req(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(n));
        requests_.push_back(req);
        // ICF response, RSV, GCT, the request's source as destination and its destination
        // as source, the SID, MRC SRC, end code 00 00, data.
        tx_ = {0xC0,   0x00,   0x02,    req[6],  req[7], req[8], req[3], req[4],
               req[5], req[9], req[10], req[11], 0x00,   0x00,   0x00,   42};
        boost::system::error_code ignored;
        socket_.send_to(net::buffer(tx_), peer_, 0, ignored);
    }
    net::ip::udp::socket socket_;
    net::ip::udp::endpoint peer_;
    std::array<std::uint8_t, 2048> rx_{};
    std::vector<std::uint8_t> tx_;
    std::vector<std::vector<std::uint8_t>> requests_;
};

struct Events : PollerEvents {
    std::optional<std::uint16_t> speed;
    std::optional<bool> online;
    void group_done(const GroupSample& sample) override {
        const auto& s = sample.tags[0];
        if (!s.error) speed = s.value.words[0];
    }
    void status_changed(const PlcStatus& status) override { online = status.online; }
    void write_done(const Plc&, const WriteResponse&) override {}
};

BridgeConfig config(std::uint16_t port, const std::string& dest_line) {
    return test::parse_ok("[[plc]]\nname = \"p\"\nhost = \"127.0.0.1\"\nport = " +
                          std::to_string(port) + "\n" + dest_line +
                          "[[plc.group]]\nname = \"g\"\ninterval_ms = 50\n"
                          "tags = [{name = \"speed\", address = \"D100\", type = \"int16\"}]\n");
}

// Runs the poller until its first cycle published a value (bounded: 5 s).
void poll_once(net::io_context& io, const Plc& plc, Events& events) {
    PlcPoller poller(io, plc, 0.0, events, 1);
    poller.start();
    const auto until = std::chrono::steady_clock::now() + 5s;
    while (!events.speed && std::chrono::steady_clock::now() < until)
        io.run_one_for(100ms);
    poller.stop();
}

// W342 (../shared/fins-frames.md): DA1 00 is "internal communications inside the local
// PLC". A [[plc]] with dest = "0.0.0" has always been sent as written; the client must
// not derive node 1 from 127.0.0.1 for it.
TEST(PollerEngine, W342DestinationNode00IsSentAsWritten) {
    net::io_context io;
    RecordingResponder plc(io);
    const auto c = config(plc.port(), "dest = \"0.0.0\"\n");
    ASSERT_EQ(c.plcs.size(), 1u);
    Events events;
    poll_once(io, c.plcs[0], events);
    ASSERT_TRUE(events.speed) << "no cycle completed";
    EXPECT_EQ(*events.speed, 42);
    EXPECT_EQ(events.online, std::optional<bool>(true));
    ASSERT_FALSE(plc.requests().empty());
    for (const auto& r : plc.requests())
        EXPECT_EQ(r[4], 0) << "DA1 as written";
}

// Without dest the node comes from the IP's last number, on loopback too (127.0.0.1: 1).
TEST(PollerEngine, WithoutDestTheNodeIsTheLastNumberOfTheIp) {
    net::io_context io;
    RecordingResponder plc(io);
    const auto c = config(plc.port(), "");
    Events events;
    poll_once(io, c.plcs[0], events);
    ASSERT_TRUE(events.speed) << "no cycle completed";
    ASSERT_FALSE(plc.requests().empty());
    EXPECT_EQ(plc.requests()[0][4], 1);
    EXPECT_EQ(plc.requests()[0][7], 254) << "source differs from the destination";
}

}  // namespace
}  // namespace fins::bridge
