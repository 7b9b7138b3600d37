// fins::put_file / get_file through a UDP proxy that drops 20 %, duplicates 5 % and
// delays 10 % of datagrams (both directions, seeded) to the real finsd server (W342
// 5-3-33 / 5-3-34). A chunk that overtakes a lost one is refused 1103 (position past
// the file's end); a retransmitted chunk the PLC had executed arrives twice. Whatever
// the network does, the transfer completes and the file is byte for byte the data.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "client/lossy_proxy.hpp"
#include "fins/client.hpp"
#include "fins/commands/file_memory.hpp"
#include "integration/support/server_fixture.hpp"

using namespace fins;
using namespace fins::test;
using namespace std::chrono_literals;

namespace {

std::vector<std::uint8_t> pattern_bytes(std::size_t n, std::uint32_t seed) {
    std::vector<std::uint8_t> out(n);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = static_cast<std::uint8_t>(i * 13 + i / 256 + seed);
    return out;
}

void put_through_faults(std::uint32_t seed, bool replace) {
    server::ServerOptions so;
    so.tcp = false;  // the proxy speaks UDP
    ServerThread server(so);
    Faults faults;
    faults.seed = seed;
    LossyUdpProxy proxy(server.port(), faults);
    ClientOptions options;
    options.port = proxy.port();
    // Under wine on a loaded host, an answer through the proxy came up to a second late
    // (docs/windows.md): all 16 attempts of 50 ms missed there, so wine's are longer.
#ifdef _WIN32
    options.timeout = 150ms;
#else
    options.timeout = 50ms;
#endif
    options.retries = 15;             // the most W596 allows: a chunk lost 16 times fails
    options.sid_quarantine = 1000ms;  // margin for starved threads on a loaded machine
    auto client = Client::connect(options);
    ASSERT_TRUE(client) << client.error().message();
    const auto name = *FileName::from("LOSSY.BIN");
    // 60 chunks of 1,976 bytes, 8 in flight.
    const auto data = pattern_bytes(60 * 1976 + 123, seed);
    if (replace) {
        const std::vector<std::uint8_t> old(5000, 0xEE);
        auto direct = server.client(false);
        ASSERT_TRUE(direct);
        ASSERT_TRUE(put_file(*direct, disk_memory_card, "", name, old, false));
    }
    const auto put = put_file(**client, disk_memory_card, "", name, data, replace);
    ASSERT_TRUE(put) << put.error().message();

    auto direct = server.client(false);
    ASSERT_TRUE(direct);
    const auto stored = get_file(*direct, disk_memory_card, "", name);
    ASSERT_TRUE(stored) << stored.error().message();
    EXPECT_EQ(stored->size(), data.size());
    EXPECT_TRUE(*stored == data) << "the file differs from what was put";
    // Read back through the same faults too.
    const auto got = get_file(**client, disk_memory_card, "", name);
    ASSERT_TRUE(got) << got.error().message();
    EXPECT_TRUE(*got == data);
    const auto c = proxy.counts();
    EXPECT_GT(c.dropped, 0u);
    EXPECT_GT(c.duplicated, 0u);
    EXPECT_GT(c.delayed, 0u);
    ::testing::Test::RecordProperty("retransmitted",
                                    static_cast<int>((*client)->stats().retransmitted));
}

TEST(FileTransferThroughLoss, W342_5_3_34_PutCompletesIdenticalThroughLossAndReordering) {
    for (std::uint32_t seed = 1; seed <= 3; ++seed) {
        SCOPED_TRACE(seed);
        put_through_faults(seed, false);
    }
}

TEST(FileTransferThroughLoss, W342_5_3_34_PutReplacingCompletesIdenticalThroughLoss) {
    for (std::uint32_t seed = 4; seed <= 5; ++seed) {
        SCOPED_TRACE(seed);
        put_through_faults(seed, true);
    }
}

}  // namespace
