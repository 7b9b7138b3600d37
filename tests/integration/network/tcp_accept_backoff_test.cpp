// finsd out of file descriptors (issue: the accept loop spun at full CPU and flooded
// the log): a child finsd under `ulimit -n 24` is flooded with connections until accept
// fails, keeps serving UDP and its open connection, logs the failure a bounded number of
// times and accepts again by itself once descriptors are free. Every wait is bounded and
// waits on an event (a log line, a response); no sleeps.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "integration/support/finsd_process.hpp"
#include "integration/support/raw_socket.hpp"

namespace fins::test {
namespace {

using namespace std::chrono_literals;

TEST(TcpAccept, OutOfDescriptorsBacksOffLogsOncePerIntervalAndRecovers) {
    // Log level info: the start-up lines format before descriptors run out. Under UBSan
    // a dynamic type's check that misses its cache needs a pipe (to probe the vtable's
    // memory), so once no descriptor is left any object is reported as an "invalid vptr"
    // (CI: the error_code of the failed accept): a sanitizer artifact, not a finsd fault.
    // tests/ubsan_no_descriptors.supp turns that check off for this finsd alone.
    const std::string supp = FINS_SOURCE_DIR "/tests/ubsan_no_descriptors.supp";
    Finsd finsd({"--max-connections", "64", "--tcp-max-pending", "64"},
                {.log_level = "info",
                 .shell = "export UBSAN_OPTIONS=\"$UBSAN_OPTIONS:suppressions=" + supp +
                          "\"; ulimit -n 24 && "});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    const auto port = finsd.port();
    std::vector<std::string> log;  // its stderr, read up to each event waited for
    auto udp = finsd.client(false);
    auto tcp = finsd.client(true);
    ASSERT_TRUE(udp && tcp);
    const Address d0{Area::dm, 0, 0, {}};

    asio::io_context io;
    std::vector<RawTcp> flood;
    std::vector<std::uint8_t> handshake(20);
    ByteWriter w{handshake};
    write_node_address_request(w, 0);
    for (int i = 0; i < 40; ++i) {
        flood.emplace_back(io, "127.0.0.1", port);
        flood.back().send(handshake);
    }
    ASSERT_TRUE(finsd.child().wait_for_stderr("accept failed", 20s, &log))
        << fmt::format("{}", fmt::join(log, "\n"));
    const auto failing_since = std::chrono::steady_clock::now();

    // Meanwhile UDP and the open connection are served.
    EXPECT_TRUE(udp->read_words(d0, 1).has_value());
    EXPECT_TRUE(tcp->read_words(d0, 1).has_value());

    // Closing the flood frees descriptors; finsd accepts again without help.
    flood.clear();
    ASSERT_TRUE(finsd.child().wait_for_stderr("accepting again", 20s, &log));
    const auto failing_for = std::chrono::steady_clock::now() - failing_since;
    RawTcp late(io, "127.0.0.1", port);
    EXPECT_EQ(be32(late.handshake(), 12), 0u);
    EXPECT_TRUE(tcp->read_words(d0, 1).has_value());

    const auto rest = finsd.stop();
    EXPECT_EQ(rest.exit_code, 0) << rest.err;
    // Up to the recovery: the first failure, at most one report per 10 s interval, and
    // the recovery line. The spinning loop wrote thousands of lines in that time. (After
    // it, accepting the closed flood can run out of descriptors again: a new episode.)
    std::size_t accept_lines = 0;
    std::string lines;
    for (const auto& line : log)
        if (line.find("fins/tcp: accept") != std::string::npos) {
            ++accept_lines;
            lines += line + "\n";
        }
    const auto intervals = static_cast<std::size_t>(failing_for / 10s);
    EXPECT_LE(accept_lines, 2 + intervals) << lines;
    EXPECT_GE(accept_lines, 2u) << lines;
}

}  // namespace
}  // namespace fins::test
