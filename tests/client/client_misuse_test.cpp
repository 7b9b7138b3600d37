// fins::Client used the wrong way fails fast and says where: a synchronous call inside a
// completion callback, and error messages that name the endpoint.
#include <gtest/gtest.h>

#include <optional>
#include <system_error>

#include "client/loopback_servers.hpp"
#include "fins/client.hpp"

using namespace fins;
using namespace fins::test;
using namespace std::chrono_literals;

namespace {

Address dm(std::uint16_t word) {
    return Address{Area::dm, 0, word, std::nullopt};
}

// The header's threading rule: a callback may call async_send*() but no synchronous
// call. Such a call fails at once with called_from_callback (it used to block for the
// whole timeout and then report a false timeout).
TEST(ClientMisuse, SynchronousCallsInsideACallbackFailAtOnce) {
    UdpResponder server;
    ClientOptions options;
    options.port = server.port();
    options.timeout = 10s;
    auto client = Client::connect(options);
    ASSERT_TRUE(client);
    Client& c = **client;
    std::optional<std::error_code> words, typed, raw, no_response;
    bool chained = false;
    c.async_send(MemoryAreaRead{{0x82, 0, 0}, 1}, [&](Result<MemoryAreaReadResponse> r) {
        ASSERT_TRUE(r);
        auto w = c.read_words(dm(1), 1);
        words = w ? std::error_code{} : w.error();
        auto t = c.send(MemoryAreaRead{{0x82, 2, 0}, 1});
        typed = t ? std::error_code{} : t.error();
        auto s = c.send_raw(CommandCode{0x05, 0x01}, {});
        raw = s ? std::error_code{} : s.error();
        auto n = c.send_no_response(CommandCode{0x05, 0x01}, {});
        no_response = n ? std::error_code{} : n.error();
        c.run();  // returns at once
        // async_send stays allowed.
        c.async_send(MemoryAreaRead{{0x82, 3, 0}, 1},
                     [&chained](Result<MemoryAreaReadResponse> r2) { chained = r2.has_value(); });
    });
    c.run();
    const auto misuse = make_error_code(ClientError::called_from_callback);
    EXPECT_EQ(words, misuse);
    EXPECT_EQ(typed, misuse);
    EXPECT_EQ(raw, misuse);
    EXPECT_EQ(no_response, misuse);
    EXPECT_TRUE(chained);
    EXPECT_EQ(c.stats().timed_out, 0u);
    EXPECT_NE(misuse.message().find("callback"), std::string::npos) << misuse.message();
}

TEST(ClientErrors, DescribeNamesTheEndpoint) {
    ClientOptions v4;
    v4.port = 9600;
    EXPECT_EQ(describe_error(v4, make_error_code(asio::error::connection_refused)),
              "127.0.0.1:9600: connection refused");
    ClientOptions v6;
    v6.host = "::1";
    v6.port = 9601;
    EXPECT_EQ(endpoint_name(v6), "[::1]:9601");
    ClientOptions named;
    named.host = "plc.example";
    EXPECT_EQ(describe_error(named, make_error_code(ClientError::timeout)),
              "plc.example:9600: no response within the timeout");
}

}  // namespace
