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

#include "integration/support/server_fixture.hpp"
#include "integration/tshark/tshark_support.hpp"

namespace fins::test {
namespace {

using tshark::severity_warning;
using tshark::split;

struct Row {
    std::string tcp_command, command, area, address, count, end_code, malformed, severity;
};

const std::vector<std::string> fields{"omron.tcp.command",      "omron.command",
                                      "omron.memory.area.read", "omron.memory.address",
                                      "omron.memory.numitems",  "omron.response.code",
                                      "_ws.malformed",          "_ws.expert.severity"};

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
    ServerThread server;
    tshark::Capture capture(server.port(), "memory");
    if (!capture.ready())
        GTEST_SKIP() << "tshark missing, or no permission to capture on lo (root or wireshark)";

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
    // The last exchange, 0F 01 over both transports, is 4 frames.
    const RunResult decoded = capture.read_until(
        fields, [](const RunResult& d) { return tshark::count_rows(d, 1, "0x0f01") == 4; });
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    const std::vector<Row> rows = parse_rows(decoded.out);
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
}

}  // namespace
}  // namespace fins::test
