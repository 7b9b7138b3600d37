// fins::Client through a UDP proxy that drops 20 %, duplicates 5 % and delays 10 % of
// datagrams (both directions, seeded): a read answer carries no address, only the
// service ID, so a late answer matched to a later request returns another address's
// value with no error. Every read here targets a word with a unique value; whatever
// the network does, a read returns its own word or fails, never another word.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <system_error>

#include "client/loopback_servers.hpp"
#include "client/lossy_proxy.hpp"
#include "fins/client.hpp"

using namespace fins;
using namespace fins::test;
using namespace std::chrono_literals;

namespace {

constexpr std::uint16_t read_count = 5000;

// A bijection on 16 bits (odd multiplier): word i holds a value no other word holds.
std::uint16_t value_of(std::uint16_t word) {
    return static_cast<std::uint16_t>(word * 40503u + 12345u);
}

// Keeps `window` reads in flight until `read_count` have been issued.
struct Driver {
    explicit Driver(Client& c) : client(c) {}
    Client& client;
    std::uint16_t next = 0;
    std::size_t ok = 0;
    std::size_t wrong = 0;
    std::map<std::string, std::size_t> errors;

    void issue() {
        const std::uint16_t word = next++;
        client.async_send(MemoryAreaRead{{0x82, word, 0}, 1},
                          [this, word](Result<MemoryAreaReadResponse> r) {
                              if (!r) {
                                  ++errors[r.error().message()];
                              } else if (r->data.size() == 2 &&
                                         ((r->data[0] << 8) | r->data[1]) == value_of(word)) {
                                  ++ok;
                              } else {
                                  ++wrong;
                              }
                              if (next < read_count) issue();
                          });
    }
};

void run_through_faults(std::uint32_t seed, std::size_t window) {
    UdpResponder server;
    server.with_plc([](FakePlc& plc) {
        for (std::uint16_t i = 0; i < read_count; ++i)
            plc.dm[i] = value_of(i);
    });
    Faults faults;
    faults.seed = seed;
    LossyUdpProxy proxy(server.port(), faults);
    ClientOptions options;
    options.port = proxy.port();
    options.timeout = 50ms;
    options.retries = 5;
    // The guarantee holds while no answer comes later than the quarantine: here a
    // request and its answer may each be held 60 ms, plus scheduling on a loaded machine
    // (CI runs two ASan tests at once: a proxy or server thread starved for 250 ms let a
    // late answer through, so the margin is a second). Under wine on a loaded host,
    // answers came up to that second late, and the 336 to 962 reads that took another
    // word's value before the quarantine followed the network (engine/sid_pool.hpp) were
    // the ones that came later still.
    options.sid_quarantine = 1000ms;
    auto client = Client::connect(options);
    ASSERT_TRUE(client) << client.error().message();
    Driver driver(**client);
    for (std::size_t i = 0; i < window; ++i)
        driver.issue();
    (*client)->run();

    EXPECT_EQ(driver.wrong, 0u) << "reads completed with another word's value";
    std::size_t failed = 0;
    for (const auto& [message, n] : driver.errors) {
        failed += n;
        EXPECT_EQ(message, make_error_code(ClientError::timeout).message()) << n << " times";
    }
    EXPECT_EQ(driver.ok + driver.wrong + failed, read_count);
    // Retries get most reads through. Under wine on a loaded host, answers come up to a
    // second late and 38 % of the reads got through (docs/windows.md): there the check is
    // only that the reads were not all lost, which would make the one above hollow.
#ifdef _WIN32
    EXPECT_GT(driver.ok, read_count / 5u) << "a fifth of the reads get through";
#else
    EXPECT_GT(driver.ok, read_count / 2u) << "retries get most reads through";
#endif
    const auto c = proxy.counts();
    EXPECT_GT(c.dropped, 0u);
    EXPECT_GT(c.duplicated, 0u);
    EXPECT_GT(c.delayed, 0u);
    const auto s = (*client)->stats();
    ::testing::Test::RecordProperty("retransmitted", static_cast<int>(s.retransmitted));
    ::testing::Test::RecordProperty("stale_discarded", static_cast<int>(s.stale_discarded));
    ::testing::Test::RecordProperty("quarantined", static_cast<int>(s.quarantined));
    ::testing::Test::RecordProperty("waited_for_id", static_cast<int>(s.waited_for_id));
    ::testing::Test::RecordProperty("quarantine_raised", static_cast<int>(s.quarantine_raised));
}

// W596 SendCmd (p. 3-16): timeout and retries; frames 1.1: the SID is all that ties an
// answer to its request.
TEST(SendCmdServiceId, LateAnswersNeverCompleteAnotherReadWith200InFlight) {
    run_through_faults(1, 200);
}

TEST(SendCmdServiceId, LateAnswersNeverCompleteAnotherReadWith32InFlight) {
    run_through_faults(2, 32);
}

}  // namespace
