// FINS/TCP under hostile or careless clients (W421 7-4, frames-networks 3.3, README
// "FINS/TCP identity and limits"): the handshake's node is the connection's identity,
// handshake checks, closing after a refusal without a reset, and the deadlines and
// cap that keep stalled sockets from locking other clients out. Every wait is a
// blocking read bounded by SO_RCVTIMEO (raw_socket.hpp); no sleeps.
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>

#include <cerrno>
#include <functional>
#include <memory>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "integration/support/raw_socket.hpp"
#include "plc/plc.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using namespace std::chrono_literals;

// The real Server on its own thread, its PLC prepared before the thread starts.
class InProcessFinsd {
  public:
    explicit InProcessFinsd(
        server::ServerOptions options,
        const std::function<void(plc::Plc&)>& setup = [](plc::Plc&) {}) {
        options.port = 0;
        setup(plc_);
        auto s = server::Server::start(io_, plc_, options);
        if (!s) throw std::runtime_error("server start: " + s.error().message());
        server_ = std::move(*s);
        port_ = server_->tcp_port();
        thread_ = std::thread([this] { io_.run(); });
    }
    ~InProcessFinsd() {
        asio::post(io_, [this] {
            server_->stop();
            io_.stop();
        });
        thread_.join();
    }
    InProcessFinsd(const InProcessFinsd&) = delete;
    InProcessFinsd& operator=(const InProcessFinsd&) = delete;
    RawTcp connect() { return RawTcp(client_io_, "127.0.0.1", port_); }

  private:
    asio::io_context io_{1};
    asio::io_context client_io_;
    plc::Plc plc_;
    std::unique_ptr<server::Server> server_;
    std::uint16_t port_ = 0;
    std::thread thread_;
};

// Limits that never fire during a test unless the test shortens one of them.
server::ServerOptions calm() {
    server::ServerOptions o;
    o.tcp_limits.handshake_timeout = 60s;
    o.tcp_limits.frame_timeout = 60s;
    o.tcp_limits.idle_timeout = 0ms;
    return o;
}

std::vector<std::uint8_t> frame(CommandCode code, const std::vector<std::uint8_t>& params,
                                std::uint8_t sid, std::uint8_t source_node,
                                std::uint8_t source_network = 0) {
    auto f = request_frame(code, params, sid, source_node);
    f[6] = source_network;  // SNA
    return tcp_packet(TcpCommand::frame, f);
}

const std::vector<std::uint8_t> d0 = {0x82, 0, 0, 0, 0, 1};
const std::vector<std::uint8_t> write_d0_1234 = {0x82, 0, 0, 0, 0, 1, 0x12, 0x34};
const std::vector<std::uint8_t> program_ffff = {0xFF, 0xFF};

std::uint8_t sid_of(const std::vector<std::uint8_t>& packet) {
    return packet.size() > tcp_header_size + 9 ? packet[tcp_header_size + 9] : 0;
}

// Reads what follows a notice: true only for a clean end of stream (FIN), false for a
// reset, more data or the receive timeout.
bool ends_with_fin(RawTcp& c) {
    auto rest = c.receive_packet();
    return rest.empty() && c.last_error() == asio::error::eof;
}

// After ends_with_fin(): our own shutdown must find the connection intact and end it
// without an error. A reset from the server leaves it CLOSE (shutdown: ENOTCONN) or
// with SO_ERROR set. Waits (bounded) until the kernel reports the connection closed.
bool ends_without_reset(RawTcp& c) {
    const int fd = c.native_handle();
    if (::shutdown(fd, SHUT_WR) != 0) return false;
    tcp_info info{};
    for (int i = 0; i < 500; ++i) {
        socklen_t size = sizeof info;
        ::getsockopt(fd, IPPROTO_TCP, TCP_INFO, &info, &size);
        if (info.tcpi_state == TCP_CLOSE) break;
        pollfd p{fd, POLLERR, 0};
        ::poll(&p, 1, 10);
    }
    int error = 0;
    socklen_t size = sizeof error;
    ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &size);
    return info.tcpi_state == TCP_CLOSE && error == 0;
}

TEST(TcpIdentity, W421_7_4_FrameFromAnotherNodeIsNotExecuted) {
    // Every node but 0.10 is write-protected; the client is given node 239 and claims 10.
    InProcessFinsd finsd(calm(), [](plc::Plc& plc) {
        plc.set_network_write_protection_setting(
            {plc::NetworkWriteProtection::all_except_listed, {NodeAddress{0, 10, 0}}});
    });
    auto c = finsd.connect();
    ASSERT_EQ(be32(c.handshake(0), 16), 239u);
    c.send(frame({0x01, 0x02}, write_d0_1234, 1, 10));
    c.send(frame({0x01, 0x01}, d0, 2, 239));
    // The claimed frame got no answer (responses come in order) and wrote nothing.
    const auto read = c.receive_packet();
    ASSERT_EQ(read.size(), tcp_header_size + 16);
    EXPECT_EQ(sid_of(read), 2);
    EXPECT_EQ(end_code_of(read, tcp_header_size), 0x0000);
    EXPECT_EQ(read[tcp_header_size + 14], 0x00);
    EXPECT_EQ(read[tcp_header_size + 15], 0x00);
    // As itself the client is protected (W342 5-1-2 note 5: 2102).
    c.send(frame({0x01, 0x02}, write_d0_1234, 3, 239));
    EXPECT_EQ(end_code_of(c.receive_packet(), tcp_header_size), 0x2102);
    // Another network's node is not this connection either.
    c.send(frame({0x01, 0x02}, write_d0_1234, 4, 239, 5));
    c.send(frame({0x01, 0x01}, d0, 5, 239));
    EXPECT_EQ(sid_of(c.receive_packet()), 5);
}

TEST(TcpIdentity, W421_7_4_AccessRightHolderCannotBeImpersonated) {
    InProcessFinsd finsd(calm());
    auto holder = finsd.connect();
    ASSERT_EQ(be32(holder.handshake(0), 16), 239u);
    holder.send(frame({0x0C, 0x01}, program_ffff, 1, 239));  // ACCESS RIGHT ACQUIRE
    ASSERT_EQ(end_code_of(holder.receive_packet(), tcp_header_size), 0x0000);

    auto other = finsd.connect();
    ASSERT_EQ(be32(other.handshake(0), 16), 240u);
    other.send(frame({0x0C, 0x02}, program_ffff, 2, 239));  // RELEASE, as the holder
    other.send(frame({0x0C, 0x01}, program_ffff, 3, 240));  // ACQUIRE, as itself
    const auto r = other.receive_packet();
    EXPECT_EQ(sid_of(r), 3);
    // W342 5-3-24: still held by node 239.
    EXPECT_EQ(end_code_of(r, tcp_header_size), 0x3001);
}

TEST(TcpHandshake, W421_7_4_NodeAbove254IsOutOfRangeNotItsLowByte) {
    InProcessFinsd finsd(calm());
    auto c = finsd.connect();
    auto request = tcp_packet(TcpCommand::node_address_request, {0x00, 0x00, 0x01, 0x05});
    c.send(request);
    const auto r = c.receive_packet();
    ASSERT_EQ(r.size(), 24u);
    EXPECT_EQ(be32(r, 8), 1u);
    EXPECT_EQ(be32(r, 12), 0x23u);  // client node out of range
    EXPECT_EQ(be32(r, 16), 0x105u);
    EXPECT_TRUE(ends_with_fin(c));
    // Node 5 is still free.
    auto five = finsd.connect();
    EXPECT_EQ(be32(five.handshake(5), 12), 0u);
}

TEST(TcpHandshake, W421_7_4_DuplicateNodeConfirmsTheOldConnectionAndRefusesTheNew) {
    InProcessFinsd finsd(calm());
    auto first = finsd.connect();
    ASSERT_EQ(be32(first.handshake(20), 12), 0u);
    auto second = finsd.connect();  // same IP address, same node
    const auto refused = second.handshake(20);
    EXPECT_EQ(be32(refused, 12), 0x21u);
    EXPECT_TRUE(ends_with_fin(second));
    // The old connection got CONNECTION CONFIRMATION (command 6, error 0) and works on.
    const auto confirmation = first.receive_packet();
    ASSERT_EQ(confirmation.size(), 16u);
    EXPECT_EQ(be32(confirmation, 8), 6u);
    EXPECT_EQ(be32(confirmation, 12), 0u);
    first.send(frame({0x01, 0x01}, d0, 7, 20));
    const auto r = first.receive_packet();
    EXPECT_EQ(sid_of(r), 7);
    EXPECT_EQ(end_code_of(r, tcp_header_size), 0x0000);
}

// The peer's unread bytes would make a plain close() send RST; a notice must instead be
// followed by FIN (shutdown of the sending side, then draining).
TEST(TcpHandshake, RefusalIsFollowedByFinNotResetWhenThePeerKeepsSending) {
    InProcessFinsd finsd(calm());
    std::vector<std::uint8_t> flood(64 * 1024, 0x55);
    {
        auto c = finsd.connect();
        auto request = tcp_packet(TcpCommand::node_address_request, {0, 0, 0, 0xFF});
        request.insert(request.end(), flood.begin(), flood.end());
        c.send(request);
        const auto r = c.receive_packet();
        ASSERT_EQ(r.size(), 24u);
        EXPECT_EQ(be32(r, 12), 0x23u);
        EXPECT_TRUE(ends_with_fin(c));
        EXPECT_TRUE(ends_without_reset(c));
    }
    auto c = finsd.connect();
    ASSERT_EQ(be32(c.handshake(), 12), 0u);
    auto bad = tcp_packet(TcpCommand::frame, request_frame({0x01, 0x01}, d0));
    bad[0] = 'X';
    bad.insert(bad.end(), flood.begin(), flood.end());
    c.send(bad);
    const auto r = c.receive_packet();
    ASSERT_EQ(r.size(), 16u);
    EXPECT_EQ(be32(r, 8), 3u);
    EXPECT_TRUE(ends_with_fin(c));
    EXPECT_TRUE(ends_without_reset(c));
}

TEST(TcpLimits, SilentSocketIsClosedAtTheHandshakeDeadline) {
    auto o = calm();
    o.tcp_limits.handshake_timeout = 200ms;
    InProcessFinsd finsd(o);
    auto c = finsd.connect();
    EXPECT_TRUE(c.closed_by_peer());
}

TEST(TcpLimits, PacketStalledMidwayIsClosedAtTheFrameDeadline) {
    auto o = calm();
    o.tcp_limits.frame_timeout = 200ms;
    InProcessFinsd finsd(o);
    auto c = finsd.connect();
    ASSERT_EQ(be32(c.handshake(), 12), 0u);
    const auto packet = frame({0x01, 0x01}, d0, 1, 239);
    c.send({packet.begin(), packet.begin() + 10});
    EXPECT_TRUE(c.closed_by_peer());
}

TEST(TcpLimits, SixteenIdleAndSixteenStalledSocketsNoLongerLockOthersOut) {
    auto o = calm();
    o.tcp_limits.handshake_timeout = 300ms;
    o.tcp_limits.idle_timeout = 300ms;
    InProcessFinsd finsd(o);
    std::vector<RawTcp> idle;
    for (int i = 0; i < 16; ++i) {
        idle.push_back(finsd.connect());
        ASSERT_EQ(be32(idle.back().handshake(), 12), 0u);
    }
    std::vector<RawTcp> stalled;
    for (int i = 0; i < 16; ++i)
        stalled.push_back(finsd.connect());
    for (auto& c : idle)
        EXPECT_TRUE(c.closed_by_peer());
    for (auto& c : stalled)
        EXPECT_TRUE(c.closed_by_peer());
    auto now_in = finsd.connect();
    EXPECT_EQ(be32(now_in.handshake(), 12), 0u);
}

TEST(TcpLimits, CapOnUnfinishedHandshakesClosesTheOldest) {
    auto o = calm();
    o.tcp_limits.max_pending = 2;
    InProcessFinsd finsd(o);
    auto oldest = finsd.connect();
    auto second = finsd.connect();
    auto third = finsd.connect();  // accepted third: the oldest goes
    EXPECT_TRUE(oldest.closed_by_peer());
    EXPECT_EQ(be32(second.handshake(), 12), 0u);
    EXPECT_EQ(be32(third.handshake(), 12), 0u);
}

// Issue 18 item 7: every handshake and every refusal logged an info line (5 MB in 10 s
// of churn), and a refusal showed the node as 0x000000ff. Now each kind of line comes at
// most once per interval (log_summary.hpp) and the refused node is decimal, with why.
TEST(TcpLogVolume, ChurnOfConnectionsLogsAFewLinesNotOnePerConnection) {
    std::ostringstream captured;
    const auto previous = spdlog::default_logger();
    const auto previous_level = spdlog::get_level();
    spdlog::set_default_logger(std::make_shared<spdlog::logger>(
        "capture", std::make_shared<spdlog::sinks::ostream_sink_mt>(captured)));
    spdlog::set_level(spdlog::level::info);
    {
        InProcessFinsd finsd(calm());
        for (int i = 0; i < 200; ++i) {
            auto c = finsd.connect();
            c.handshake(0);
        }
        for (int i = 0; i < 50; ++i) {
            auto c = finsd.connect();
            c.send(tcp_packet(TcpCommand::node_address_request, {0x00, 0x00, 0x00, 0xFF}));
            c.receive_packet();
        }
    }
    spdlog::set_default_logger(previous);
    spdlog::set_level(previous_level);
    const std::string log = captured.str();
    std::size_t lines = 0;
    for (const char ch : log)
        lines += ch == '\n' ? 1U : 0U;
    EXPECT_LE(lines, 6u) << log;
    EXPECT_NE(log.find("refused client node 255: the client FINS node address is out of range"),
              std::string::npos)
        << log;
    EXPECT_EQ(log.find("0x000000ff"), std::string::npos) << log;
}

}  // namespace
}  // namespace fins::test
