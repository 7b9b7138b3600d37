// Conformance oracle: Wireshark's FINS dissector decodes what our client and server
// exchange on loopback. It must flag nothing as malformed (no expert warning or error)
// and read back the command code, area code, address, count and end code we meant.
//
// Needs tshark (Debian package) and permission to capture on `lo` (root, as in CI);
// without them the test is skipped with the reason.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "process.hpp"
#include "server_fixture.hpp"

namespace fins::test {
namespace {

constexpr const char* tshark = "/usr/bin/tshark";
// Expert-info severities as tshark prints them (epan/proto.h PI_WARN, PI_ERROR).
constexpr long severity_warning = 0x00600000;

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : s) {
        if (c == sep) {
            out.push_back(cur);
            cur.clear();
        } else {
            cur += c;
        }
    }
    out.push_back(cur);
    return out;
}

struct Row {
    std::string tcp_command, command, area, address, count, end_code, malformed, severity;
};

RunResult decode(const std::string& capture, const std::string& port) {
    return run({tshark,
                "-r",
                capture,
                "-d",
                "udp.port==" + port + ",omron",
                "-d",
                "tcp.port==" + port + ",omron",
                "-Y",
                "omron",
                "-T",
                "fields",
                "-E",
                "separator=|",
                "-e",
                "omron.tcp.command",
                "-e",
                "omron.command",
                "-e",
                "omron.memory.area.read",
                "-e",
                "omron.memory.address",
                "-e",
                "omron.memory.numitems",
                "-e",
                "omron.response.code",
                "-e",
                "_ws.malformed",
                "-e",
                "_ws.expert.severity"});
}

std::vector<Row> parse_rows(const std::string& out) {
    std::vector<Row> rows;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);) {
        auto f = split(line, '|');
        if (f.size() != 8) {
            ADD_FAILURE() << "unexpected tshark line: " << line;
            continue;
        }
        rows.push_back({f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7]});
    }
    return rows;
}

TEST(Tshark, DissectorReadsOurUdpAndTcpTrafficWithoutComplaint) {
    if (!std::filesystem::exists(tshark)) GTEST_SKIP() << "tshark is not installed";
    ServerThread server;
    const auto dir =
        std::filesystem::temp_directory_path() / ("fins-tshark-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto capture = (dir / "capture.pcapng").string();
    const std::string port = std::to_string(server.port());

    Child dump({tshark, "-i", "lo", "-f", "port " + port, "-w", capture});
    if (!dump.wait_for_stderr("Capture started"))
        GTEST_SKIP() << "cannot capture on lo (needs root or the wireshark group)";

    // Traffic: every 01 xx command over both transports, plus end-code answers.
    for (bool tcp : {false, true}) {
        auto c = server.client(tcp);
        ASSERT_NE(c, nullptr);
        const std::vector<std::uint8_t> two_words{0x12, 0x34, 0x56, 0x78};
        ASSERT_TRUE(c->send(MemoryAreaWrite{{0x82, 0x000A, 0}, 2, two_words}).has_value());
        ASSERT_TRUE(c->send(MemoryAreaRead{{0x82, 0x000A, 0}, 2}).has_value());
        ASSERT_TRUE(c->send(MemoryAreaRead{{0x30, 0x000A, 0x0D}, 3}).has_value());
        ASSERT_TRUE(c->send(MemoryAreaFill{{0xB1, 0x0005, 0}, 4, 0xAAAA}).has_value());
        ASSERT_TRUE(
            c->send(MultipleMemoryAreaRead{{{0x82, 0x000A, 0}, {0x31, 0x0003, 1}}}).has_value());
        ASSERT_TRUE(
            c->send(MemoryAreaTransfer{{0x82, 0x000A, 0}, {0xB2, 0x0000, 0}, 2}).has_value());
        EXPECT_FALSE(c->send(MemoryAreaRead{{0x82, 0x8000, 0}, 1}).has_value());  // 1103
        EXPECT_TRUE(c->send_raw({0x0F, 0x01}, {}).has_value());                   // 0401
    }
    // The kernel hands captured packets to dumpcap in blocks and dumpcap drops the
    // unfinished block when stopped, so read the growing file (bounded) until the last
    // exchange (0F 01 over both transports, 4 frames) is in it, then stop the capture.
    RunResult decoded;
    std::vector<Row> rows;
    for (int attempt = 0; attempt < 60; ++attempt) {
        decoded = decode(capture, port);
        rows = parse_rows(decoded.out);
        int undefined = 0;
        for (const auto& r : rows)
            undefined += r.command == "0x0f01" ? 1 : 0;
        if (undefined == 4) break;
    }
    dump.terminate(SIGINT);
    dump.wait();
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    SCOPED_TRACE("tshark fields:\n" + decoded.out + decoded.err);
    std::map<std::string, int> commands;
    std::map<std::string, int> end_codes;
    std::map<std::string, int> requests;  // "command area address count"
    for (const auto& r : rows) {
        EXPECT_TRUE(r.malformed.empty()) << "malformed: " << r.command;
        if (!r.command.empty()) ++commands[r.command];
        if (!r.end_code.empty()) ++end_codes[r.end_code];
        if (!r.count.empty())
            ++requests[r.command + " " + r.area + " " + r.address + " " + r.count];
        // 0F 01 is sent on purpose to get 0401; the dissector rightly warns that it does
        // not know the command, so only that exchange may carry a warning.
        if (r.command == "0x0f01") continue;
        for (const auto& s : split(r.severity, ',')) {
            if (!s.empty()) {
                EXPECT_LT(std::stol(s), severity_warning) << r.command;
            }
        }
    }
    // Each command crossed the wire as request and response on both transports.
    EXPECT_EQ(commands["0x0101"], 2 * 2 * 3);
    EXPECT_EQ(commands["0x0102"], 2 * 2);
    EXPECT_EQ(commands["0x0103"], 2 * 2);
    EXPECT_EQ(commands["0x0104"], 2 * 2);
    EXPECT_EQ(commands["0x0105"], 2 * 2);
    EXPECT_EQ(commands["0x0f01"], 2 * 2);
    EXPECT_EQ(requests["0x0101 0x82 0x000a 2"], 2);
    EXPECT_EQ(requests["0x0101 0x30 0x000a 3"], 2);
    EXPECT_EQ(requests["0x0102 0x82 0x000a 2"], 2);
    EXPECT_EQ(requests["0x0103 0xb1 0x0005 4"], 2);
    EXPECT_EQ(end_codes["0x1103"], 2);
    // The dissector stops at an unknown command code, so the 0401 answers are checked
    // by the integration tests rather than here.
    EXPECT_EQ(end_codes["0x0000"], 2 * 6);
    // FINS/TCP: the handshake (commands 0 and 1) and frames (2) were recognised.
    int handshake = 0;
    for (const auto& r : rows)
        if (r.tcp_command == "0x00000000" || r.tcp_command == "0x00000001") ++handshake;
    EXPECT_EQ(handshake, 2);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace fins::test
