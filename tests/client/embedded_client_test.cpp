// fins::Client embedded in the caller's io_context (Client::create, docs/client.md "One
// engine"): several clients share one loop the test runs, open by asynchronous name
// resolution, and keep the one retry rule (W596 SendCmd p. 3-16: a retry resends the
// message, same SID).
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "client/loopback_servers.hpp"
#include "fins/client.hpp"
#include "fins/commands/memory_area.hpp"
#include "integration/support/server_fixture.hpp"
#include "transport/asio.hpp"

using namespace fins;
using namespace fins::test;
using namespace std::chrono_literals;

namespace {

// Runs `io` until `done()` holds, at most 10 s of wall time.
bool run_until(asio::io_context& io, const std::function<bool()>& done) {
    const auto limit = std::chrono::steady_clock::now() + 10s;
    while (!done() && std::chrono::steady_clock::now() < limit) {
        if (io.stopped()) io.restart();
        io.run_one_for(50ms);
    }
    return done();
}

std::unique_ptr<Client> embedded(asio::io_context& io, ClientOptions options) {
    auto c = Client::create(io, std::move(options));
    EXPECT_TRUE(c) << (c ? "" : c.error().message());
    return c ? std::move(*c) : nullptr;
}

// Each client writes its own 40 words, one request per word, all in flight at once, then
// reads them back with one request.
struct Writer {
    Writer(std::unique_ptr<Client> c, std::uint16_t b) : client(std::move(c)), base(b) {}
    std::unique_ptr<Client> client;
    std::uint16_t base;
    std::size_t written = 0;
    std::size_t failed = 0;
    std::optional<std::vector<std::uint8_t>> read_back;

    void start() {
        for (std::uint16_t i = 0; i < 40; ++i) {
            const auto value = static_cast<std::uint16_t>(base + i);
            const std::array<std::uint8_t, 2> bytes{static_cast<std::uint8_t>(value >> 8),
                                                    static_cast<std::uint8_t>(value)};
            client->async_send(MemoryAreaWrite{{0x82, value, 0}, 1, bytes},
                               [this](Result<EmptyResponse> r) {
                                   r ? ++written : ++failed;
                                   if (written + failed == 40) read();
                               });
        }
    }
    void read() {
        client->async_send(MemoryAreaRead{{0x82, base, 0}, 40},
                           [this](Result<MemoryAreaReadResponse> r) {
                               if (r) read_back = r->data;
                           });
    }
    [[nodiscard]] bool done() const { return read_back.has_value() || failed > 0; }
};

TEST(EmbeddedClient, TwoClientsOnTheCallersIoContextTalkToFinsdConcurrently) {
    ServerThread finsd;  // the real server, its own thread, TCP and UDP
    asio::io_context io{1};
    ClientOptions options;
    options.port = finsd.port();
    options.protocol = ClientOptions::Protocol::tcp;
    Writer a{embedded(io, options), 100};
    Writer b{embedded(io, options), 500};
    ASSERT_TRUE(a.client && b.client);
    EXPECT_FALSE(a.client->is_connected()) << "create() opens nothing";
    a.start();
    b.start();
    EXPECT_EQ(a.client->in_flight() + b.client->in_flight(), 80u);
    ASSERT_TRUE(run_until(io, [&] { return a.done() && b.done(); }));
    for (const Writer* w : {&a, &b}) {
        EXPECT_EQ(w->written, 40u);
        EXPECT_EQ(w->failed, 0u);
        ASSERT_TRUE(w->read_back);
        ASSERT_EQ(w->read_back->size(), 80u);
        for (std::uint16_t i = 0; i < 40; ++i) {
            const auto word = static_cast<std::uint16_t>(((*w->read_back)[2u * i] << 8) |
                                                         (*w->read_back)[2u * i + 1]);
            EXPECT_EQ(word, w->base + i);
        }
    }
    // Two FINS/TCP connections, two client nodes from the handshakes.
    EXPECT_NE(a.client->source().node, b.client->source().node);
}

TEST(EmbeddedClient, AsyncSendViewHandsTheAnswerWithoutACopy) {
    server::ServerOptions so;
    so.tcp = false;
    ServerThread finsd(so);
    asio::io_context io{1};
    ClientOptions options;
    options.port = finsd.port();
    auto client = embedded(io, options);
    ASSERT_TRUE(client);
    const std::array<std::uint8_t, 8> write{0x82, 0x00, 0x0A, 0x00, 0x00, 0x01, 0x12, 0x34};
    const std::array<std::uint8_t, 6> read{0x82, 0x00, 0x0A, 0x00, 0x00, 0x01};
    std::optional<std::vector<std::uint8_t>> got;
    client->async_send_view(MemoryAreaWrite::code, write,
                            [](Result<ResponseView> r) { EXPECT_TRUE(r && r->code.ok()); });
    client->async_send_view(MemoryAreaRead::code, read, [&got](Result<ResponseView> r) {
        ASSERT_TRUE(r) << r.error().message();
        EXPECT_TRUE(r->code.ok());
        got.emplace(r->data.begin(), r->data.end());
    });
    ASSERT_TRUE(run_until(io, [&] { return got.has_value(); }));
    EXPECT_EQ(*got, (std::vector<std::uint8_t>{0x12, 0x34}));
}

TEST(EmbeddedClient, SynchronousCallsRefuseAndRunIsANoOp) {
    asio::io_context io{1};
    auto client = embedded(io, {});
    ASSERT_TRUE(client);
    auto r = client->read_words({Area::dm, 0, 0, std::nullopt}, 1);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(ClientError::called_from_callback));
    client->run();  // returns at once: only the caller runs `io`
    EXPECT_EQ(client->in_flight(), 0u);
}

TEST(EmbeddedClient, OpensByAsynchronousResolutionOfLocalhost) {
    ServerThread finsd;  // 127.0.0.1; "localhost" may give ::1 first, TCP tries the next
    asio::io_context io{1};
    ClientOptions options;
    options.host = "localhost";
    options.port = finsd.port();
    options.protocol = ClientOptions::Protocol::tcp;
    auto client = embedded(io, options);
    ASSERT_TRUE(client);
    std::optional<std::error_code> opened;
    client->async_open([&opened](std::error_code ec) { opened = ec; });
    EXPECT_FALSE(opened) << "async_open() must not resolve or connect inline";
    ASSERT_TRUE(run_until(io, [&] { return opened.has_value(); }));
    EXPECT_FALSE(*opened) << opened->message();
    EXPECT_TRUE(client->is_connected());
    // Open already: the next async_open() answers from the loop, at once.
    std::optional<std::error_code> again;
    client->async_open([&again](std::error_code ec) { again = ec; });
    EXPECT_FALSE(again);
    ASSERT_TRUE(run_until(io, [&] { return again.has_value(); }));
    EXPECT_FALSE(*again);
}

TEST(EmbeddedClient, AnUnknownHostFailsTheOpenAndTheRequestsWaitingForIt) {
    asio::io_context io{1};
    ClientOptions options;
    options.host = "no-such-host.invalid";  // RFC 6761: never resolves
    auto client = embedded(io, options);
    ASSERT_TRUE(client);
    std::optional<std::error_code> opened;
    std::optional<std::error_code> request;
    client->async_open([&opened](std::error_code ec) { opened = ec; });
    client->async_send(MemoryAreaRead{{0x82, 0, 0}, 1},
                       [&request](Result<MemoryAreaReadResponse> r) {
                           request = r ? std::error_code{} : r.error();
                       });
    ASSERT_TRUE(run_until(io, [&] { return opened && request; }));
    EXPECT_TRUE(*opened);
    EXPECT_TRUE(*request);
}

// W596 section 3, SendCmd p. 3-16, Option.Retry: "If no response is returned within
// Option.TimeOut, try to resend the message": the message, so the same frame, same SID.
TEST(EmbeddedClient, W596SendCmdP3_16RetryResendsTheSameMessageWithTheSameSid) {
    UdpResponder server;
    server.set_silent(true);
    asio::io_context io{1};
    ClientOptions options;
    options.port = server.port();
    options.timeout = 30ms;
    options.retries = 2;
    auto client = embedded(io, options);
    ASSERT_TRUE(client);
    std::optional<std::error_code> outcome;
    client->async_send(MemoryAreaRead{{0x82, 7, 0}, 1},
                       [&outcome](Result<MemoryAreaReadResponse> r) {
                           outcome = r ? std::error_code{} : r.error();
                       });
    ASSERT_TRUE(run_until(io, [&] { return outcome.has_value(); }));
    EXPECT_EQ(*outcome, make_error_code(ClientError::timeout));
    ASSERT_TRUE(server.wait_for_requests(3));
    const auto frames = server.requests();
    ASSERT_EQ(frames.size(), 3u) << "one send and `retries` resends";
    EXPECT_EQ(frames[1], frames[0]);
    EXPECT_EQ(frames[2], frames[0]);
    EXPECT_EQ(client->stats().retransmitted, 2u);
    EXPECT_EQ(client->stats().timed_out, 1u);
}

}  // namespace
