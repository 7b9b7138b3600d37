// finsd --port 0: TCP takes a free port number and FINS/UDP the same number (one port, as
// a CPU Unit's 9600). That number can already be held for UDP: every client socket's
// ephemeral port comes from the same range. finsd used to exit "cannot listen ... Address
// already in use" then, and a CI run lost a test to it (SparkplugMqtt.Refused..., finsd
// started in parallel with hundreds of client sockets). Now it looks for a pair again.
#include <unistd.h>

#include <string>

#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

// In a network namespace of its own: 8 ephemeral ports (40000-40007), the first 6 held
// for UDP, then finsd --port 0 started and stopped 4 times; one line per start, the
// "listening N" line or the exit code and stderr.
constexpr const char* held_ports_script = R"(
import socket, subprocess, sys
finsd, control = sys.argv[1], sys.argv[2]
with open('/proc/sys/net/ipv4/ip_local_port_range', 'w') as f:
    f.write('40000 40007')
held = []
for port in range(40000, 40006):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(('127.0.0.1', port))
    held.append(s)
for _ in range(4):
    c = subprocess.Popen([finsd, '--port', '0', '--bind', '127.0.0.1', '--control', control,
                          '--log-level', 'warn'],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = c.stdout.readline().strip()
    c.terminate()
    out, err = c.communicate(timeout=20)
    print(line or 'exit %d: %s' % (c.returncode, err.strip()))
)";

TEST(FinsdPortZero, TakesANumberFreeForBothTcpAndUdp) {
    if (::geteuid() != 0 || ::access("/usr/bin/unshare", X_OK) != 0)
        GTEST_SKIP() << "needs root and unshare for a network namespace";
    ScratchDir dir("port0");
    const auto r = run({"/usr/bin/unshare", "--net", "python3", "-c", held_ports_script, finsd_path,
                        (dir.path() / "finsd.sock").string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Each start found 40006 or 40007: the only numbers free for both. Before, 3 of 4
    // starts on average drew a held number and exited.
    std::size_t lines = 0;
    std::size_t from = 0;
    while (from < r.out.size()) {
        const auto end = r.out.find('\n', from);
        const auto line = r.out.substr(from, end - from);
        from = end == std::string::npos ? r.out.size() : end + 1;
        ++lines;
        EXPECT_TRUE(line == "listening 40006" || line == "listening 40007") << line;
    }
    EXPECT_EQ(lines, 4U) << r.out;
}

}  // namespace
}  // namespace fins::test
