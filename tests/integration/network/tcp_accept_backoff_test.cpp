// finsd out of file descriptors (issue: the accept loop spun at full CPU and flooded
// the log): a child finsd under `ulimit -n 24` is flooded with connections until accept
// fails, keeps serving UDP and its open connection, logs the failure a bounded number of
// times and accepts again by itself once descriptors are free. Every wait is bounded and
// waits on an event (a log line, a response); no sleeps.
#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"
#include "integration/support/raw_socket.hpp"

namespace fins::test {
namespace {

using namespace std::chrono_literals;

// Lines of finsd's output (its log is on stderr, sent to stdout here) until one contains `text`, at
// most `timeout`.
bool wait_for_log(Child& child, const std::string& text, std::vector<std::string>& seen,
                  std::chrono::seconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
        const auto line = child.read_line(std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now()));
        if (line.empty()) continue;
        seen.push_back(line);
        if (line.find(text) != std::string::npos) return true;
    }
    return false;
}

TEST(TcpAccept, OutOfDescriptorsBacksOffLogsOncePerIntervalAndRecovers) {
    // Log level info: the start-up lines format before descriptors run out. Under UBSan
    // the first check of a dynamic type needs a pipe (to probe the vtable's memory), so
    // a log line whose formatting code had never run would be reported as an "invalid
    // vptr" once no descriptor is left: a sanitizer artifact, not a finsd fault.
    Child child({"/bin/sh", "-c",
                 "ulimit -n 24 && exec " + finsd_path +
                     " --port 0 --log-level info --max-connections 64 --tcp-max-pending 64 2>&1"});
    std::vector<std::string> log;
    ASSERT_TRUE(wait_for_log(child, "listening ", log, 20s));
    const std::string listening = log.back();
    const auto port = static_cast<std::uint16_t>(std::stoul(listening.substr(10)));
    auto open_client = [port](bool tcp) {
        ClientOptions o;
        o.port = port;
        o.protocol = tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
        o.timeout = 3000ms;
        auto c = Client::connect(o);
        EXPECT_TRUE(c.has_value()) << (c ? "" : c.error().message());
        return c ? std::move(*c) : nullptr;
    };
    auto udp = open_client(false);
    auto tcp = open_client(true);
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
    ASSERT_TRUE(wait_for_log(child, "accept failed", log, 20s));
    const auto failing_since = std::chrono::steady_clock::now();

    // Meanwhile UDP and the open connection are served.
    EXPECT_TRUE(udp->read_words(d0, 1).has_value());
    EXPECT_TRUE(tcp->read_words(d0, 1).has_value());

    // Closing the flood frees descriptors; finsd accepts again without help.
    flood.clear();
    ASSERT_TRUE(wait_for_log(child, "accepting again", log, 20s));
    const auto failing_for = std::chrono::steady_clock::now() - failing_since;
    RawTcp late(io, "127.0.0.1", port);
    EXPECT_EQ(be32(late.handshake(), 12), 0u);
    EXPECT_TRUE(tcp->read_words(d0, 1).has_value());

    child.terminate();
    const auto rest = child.wait(20s);
    EXPECT_EQ(rest.exit_code, 0) << rest.out;
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
