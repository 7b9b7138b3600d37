// The FINS request paths' failure boundary (server/sessions/failure_boundary.hpp, issue
// 25): a request whose handling throws (std::bad_alloc, nlohmann::json's exceptions,
// std::out_of_range, anything) answers 0301, counts in fins_request_failures_total, and
// the session serves its next request. The test seam makes the throw; without the
// boundary it leaves io_context::run and every session of the server is gone.
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <sys/time.h>

#include <array>
#include <atomic>
#include <chrono>
#include <new>
#include <stdexcept>
#include <vector>

#include <boost/asio/ip/udp.hpp>
#include <nlohmann/json.hpp>

#include "server/frame_builder.hpp"
#include "server/metrics/metrics.hpp"
#include "server/sessions/failure_boundary.hpp"
#include "server/sessions/io_thread.hpp"
#include "server/sessions/server.hpp"
#include "server/sessions/tcp_peer.hpp"

namespace fins::test {
namespace {

enum class Throw : int { nothing, bad_alloc, json, out_of_range, no_std_type };
constexpr std::array kinds{Throw::bad_alloc, Throw::json, Throw::out_of_range, Throw::no_std_type};

std::atomic<Throw> thrown{Throw::nothing};

// What a handler could throw, thrown the way it would be.
void throw_as(Throw kind) {
    switch (kind) {
        case Throw::nothing:
            return;
        case Throw::bad_alloc:
            throw std::bad_alloc();
        case Throw::json: {
            const nlohmann::json number = 1;
            (void)number.at("key");  // type_error 304
            return;
        }
        case Throw::out_of_range: {
            const std::vector<int> none;
            (void)none.at(3);
            return;
        }
        case Throw::no_std_type:
            throw 42;
    }
}

void fault(Bytes) {
    throw_as(thrown.load());
}

std::uint64_t failures() {
    return server::metrics::process_metrics().request_failures.load();
}

// The seam set for one test, cleared whatever happens.
struct Seam {
    Seam() { server::set_request_fault_for_tests(fault); }
    ~Seam() {
        thrown = Throw::nothing;
        server::set_request_fault_for_tests(nullptr);
    }
};

Reply guarded(Harness& h, const std::vector<std::uint8_t>& frame) {
    std::array<std::uint8_t, max_frame_size> out{};
    const auto n = server::handle_guarded(h.dispatcher, frame, out, h.context);
    return Reply{{out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)}};
}

TEST(FailureBoundary, EachKindOfThrowAnswers0301AndCounts) {
    Seam seam;
    Harness h;
    const auto frame = request_frame("0101 82000000 0001");
    for (const auto kind : kinds) {
        SCOPED_TRACE(static_cast<int>(kind));
        thrown = kind;
        const auto before = failures();
        const Reply r = guarded(h, frame);
        ASSERT_FALSE(r.empty());
        EXPECT_EQ(r.end_code(), 0x0301);  // W342 5-1-3 communications controller error
        EXPECT_EQ(r.command(), (CommandCode{0x01, 0x01}));
        EXPECT_EQ(r.header().service_id, 0x5A);
        EXPECT_EQ(r.header().source, server_node);
        EXPECT_EQ(r.header().destination, client_node);
        EXPECT_TRUE(r.header().is_response());
        EXPECT_EQ(failures(), before + 1);
    }
    // The same dispatcher answers normally again.
    thrown = Throw::nothing;
    const auto before = failures();
    const Reply r = guarded(h, frame);
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(failures(), before);
}

TEST(FailureBoundary, NoAnswerWhereNoneIsWantedButStillCounted) {
    Seam seam;
    Harness h;
    thrown = Throw::bad_alloc;
    FrameFields no_response;
    no_response.icf = 0x81;  // bit 0: no response
    auto before = failures();
    EXPECT_TRUE(guarded(h, request_frame("0101 82000000 0001", no_response)).empty());
    EXPECT_EQ(failures(), before + 1);
    // Too short to carry a command code: nothing to answer to.
    before = failures();
    EXPECT_TRUE(guarded(h, {0x80, 0x00, 0x02}).empty());
    EXPECT_EQ(failures(), before + 1);
}

TEST(FailureBoundary, AnInstructionAnswerWhoseHookThrowsIsTakenAndCounted) {
    for (const auto kind : kinds) {
        SCOPED_TRACE(static_cast<int>(kind));
        const auto before = failures();
        EXPECT_TRUE(server::take_response_guarded([kind] {
            throw_as(kind);
            return false;
        }));
        EXPECT_EQ(failures(), before + 1);
    }
    const auto before = failures();
    EXPECT_FALSE(server::take_response_guarded([] { return false; }));
    EXPECT_TRUE(server::take_response_guarded([] { return true; }));
    EXPECT_EQ(failures(), before);
}

// A real server: UDP and FINS/TCP on one I/O thread, as finsd runs them.
class FailureBoundaryServer : public IoThread, public ::testing::Test {
  protected:
    void SetUp() override {
        server::ServerOptions options;
        options.port = 0;
        auto s = server::Server::start(io, plc_, options);
        ASSERT_TRUE(s) << s.error().message();
        server_ = std::move(*s);
        start_thread();
    }
    void TearDown() override {
        on_io([this] {
            server_->stop();
            return 0;
        });
        stop();
    }

    // One MEMORY AREA READ over UDP; its end code (0xFFFF: no answer in 5 s).
    std::uint16_t udp_read(std::uint8_t sid) {
        asio::io_context client_io;
        asio::ip::udp::socket s(client_io, asio::ip::udp::v4());
        timeval tv{5, 0};
        ::setsockopt(s.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
        FrameFields f;
        f.service_id = sid;
        f.destination = {0, 0, 0};
        s.send_to(asio::buffer(request_frame("0101 82000000 0001", f)),
                  {asio::ip::make_address("127.0.0.1"), server_->udp_port()});
        std::array<std::uint8_t, 64> in{};
        const auto n = ::recv(s.native_handle(), in.data(), in.size(), 0);
        if (n < 14 || in[9] != sid) return 0xFFFF;
        return static_cast<std::uint16_t>((in[12] << 8) | in[13]);
    }

    // The same over FINS/TCP (an answer of any length: 0301 carries no data).
    static std::uint16_t tcp_read(TcpPeer& tcp, std::uint8_t sid) {
        const auto packet = tcp.read_packet(sid);
        if (!tcp.send_all(packet.data(), packet.size())) return 0xFFFF;
        const auto in = tcp.receive_packet();
        if (in.size() < tcp_header_size + 14 || in[tcp_header_size + 9] != sid) return 0xFFFF;
        return static_cast<std::uint16_t>((in[tcp_header_size + 12] << 8) | in[tcp_header_size + 13]);
    }

    plc::Plc plc_;
    std::unique_ptr<server::Server> server_;
};

TEST_F(FailureBoundaryServer, SessionsKeepServingAfterEachKindOfThrow) {
    Seam seam;
    TcpPeer tcp(server_->tcp_port());
    ASSERT_TRUE(tcp.handshake());
    std::uint8_t sid = 1;
    for (const auto kind : kinds) {
        SCOPED_TRACE(static_cast<int>(kind));
        thrown = kind;
        const auto before = failures();
        EXPECT_EQ(udp_read(sid++), 0x0301);
        EXPECT_EQ(tcp_read(tcp, sid++), 0x0301);
        EXPECT_EQ(failures(), before + 2);
        // The same UDP socket and the same FINS/TCP connection serve the next request.
        thrown = Throw::nothing;
        EXPECT_EQ(udp_read(sid++), 0x0000);
        EXPECT_EQ(tcp_read(tcp, sid++), 0x0000);
    }
    // And the I/O thread still runs what is posted to it.
    EXPECT_EQ(on_io([] { return 7; }), 7);
}

}  // namespace
}  // namespace fins::test
