// Conformance oracle for 02 01 .. 02 03 and 03 06 .. 03 08: Wireshark's FINS dissector
// decodes what our client and server exchange on loopback, flags nothing as malformed
// (no expert warning or error) and reads back the parameter area codes, words, counts,
// program numbers, addresses and clear codes we meant. 02 40 is a Loop Control Board
// command the dissector does not know, so it is not sent here.
//
// Needs tshark and permission to capture on `lo`; without them the test is skipped.
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/client.hpp"
#include "fins/commands/parameter_area.hpp"
#include "fins/commands/program_area.hpp"
#include "integration/support/process.hpp"
#include "integration/support/server_fixture.hpp"
#include "integration/tshark/tshark_support.hpp"
#include "plc/plc.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using tshark::severity_warning;
using tshark::split;

const std::vector<std::string> fields = {
    "omron.command",        "omron.parameter_area_code", "omron.word",      "omron.numwords",
    "omron.program_number", "omron.word.begin",          "omron.clearcode", "omron.response.code",
    "_ws.malformed",        "_ws.expert.severity"};

std::vector<std::vector<std::string>> parse_rows(const std::string& out) {
    std::vector<std::vector<std::string>> rows;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);) {
        auto f = split(line, '|');
        if (f.size() == fields.size())
            rows.push_back(f);
        else
            ADD_FAILURE() << "unexpected tshark line: " << line;
    }
    return rows;
}

TEST(TsharkPlcData, DissectorReadsParameterAndProgramAreaTrafficWithoutComplaint) {
    ServerThread server{{}, plc::OperatingMode::program};
    tshark::Capture capture(server.port(), "plc-data");
    if (!capture.ready())
        GTEST_SKIP() << "tshark missing, or no permission to capture on lo (root or wireshark)";

    const std::vector<std::uint8_t> two_words{0x0A, 0x0B, 0x0C, 0x0D};
    const std::vector<std::uint8_t> program(8, 0x5A);
    for (bool tcp : {false, true}) {
        auto c = server.client(tcp);
        ASSERT_NE(c, nullptr);
        ASSERT_TRUE(c->send(ParameterAreaWrite{0x8013, 0x01FE, 2, true, two_words}));
        ASSERT_TRUE(c->send(ParameterAreaRead{0x8013, 0x01FE, 2, false}));
        ASSERT_TRUE(c->send(ParameterAreaRead{0x8010, 0x0000, 498, false}));
        EXPECT_FALSE(c->send(ParameterAreaRead{0x8011, 0x0000, 1, false}));  // 1101
        ASSERT_TRUE(c->send(ParameterAreaClear{0x8013, 0, 512, false, 0}));
        ASSERT_TRUE(c->send(ProgramAreaWrite{0xFFFF, 0x100, 8, true, program}));
        ASSERT_TRUE(c->send(ProgramAreaRead{0xFFFF, 0x100, 8, false}));
        ASSERT_TRUE(c->send(ProgramAreaClear{0xFFFF, clear_with_interrupt_tasks}));
    }
    // Read the growing capture (bounded) until the last exchange (03 08 over both
    // transports: 4 frames) is in it, then stop the capture.
    const RunResult decoded = capture.read_until(
        fields, [](const RunResult& d) { return tshark::count_rows(d, 0, "0x0308") == 4; });
    const auto rows = parse_rows(decoded.out);
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    SCOPED_TRACE("tshark fields:\n" + decoded.out + decoded.err);
    std::map<std::string, int> commands;
    std::map<std::string, int> seen;  // "command|area|word|numwords|program|begin|clear"
    std::map<std::string, int> end_codes;
    int malformed_error_answers = 0;
    for (const auto& r : rows) {
        if (r[0].empty()) continue;  // FINS/TCP handshake frames
        // The 4.0 dissector reads a 02 01 response's echo fields without checking that an
        // error answer carries only the end code (as every FINS unit sends it), so the
        // 1101 answers alone come out "malformed"; everything else must decode cleanly.
        if (r[0] == "0x0201" && r[1].empty()) {
            ++malformed_error_answers;
            continue;
        }
        EXPECT_TRUE(r[8].empty()) << "malformed: " << r[0];
        for (const auto& s : split(r[9], ',')) {
            if (!s.empty()) {
                EXPECT_LT(std::stol(s), severity_warning) << r[0];
            }
        }
        ++commands[r[0]];
        ++seen[r[0] + "|" + r[1] + "|" + r[2] + "|" + r[3] + "|" + r[4] + "|" + r[5] + "|" + r[6]];
        if (!r[7].empty()) ++end_codes[r[0] + " " + r[7]];
    }
    EXPECT_EQ(malformed_error_answers, 2);
    for (const char* c : {"0x0202", "0x0203", "0x0306", "0x0307", "0x0308"})
        EXPECT_EQ(commands[c], 2 * 2) << c;
    EXPECT_EQ(commands["0x0201"], 2 * 2 * 3 - 2);
    // Field by field; the read answers echo area/word or program/address with the count
    // (bit 15 on the routing tables' last word), the write answer of 03 07 its command.
    EXPECT_EQ((seen["0x0202|0x8013|0x01fe|0x8002|||"]), 2);
    EXPECT_EQ((seen["0x0201|0x8013|0x01fe|0x0002|||"]), 2);
    EXPECT_EQ((seen["0x0201|0x8013|0x01fe|0x8002|||"]), 2);
    EXPECT_EQ((seen["0x0201|0x8010|0x0000|0x01f2|||"]), 2 * 2);
    EXPECT_EQ((seen["0x0201|0x8011|0x0000|0x0001|||"]), 2);
    EXPECT_EQ((seen["0x0203|0x8013|0x0000|0x0200|||"]), 2);
    EXPECT_EQ((seen["0x0306|||0x0008|0xffff|0x00000100|"]), 2 * 2);
    EXPECT_EQ((seen["0x0307|||0x8008|0xffff|0x00000100|"]), 2 * 2);
    EXPECT_EQ((seen["0x0308||||0xffff||0x10"]), 2);
    for (const char* c : {"0x0202", "0x0203", "0x0306", "0x0307", "0x0308"})
        EXPECT_EQ(end_codes[std::string(c) + " 0x0000"], 2) << c;
    EXPECT_EQ(end_codes["0x0201 0x0000"], 2 * 2);
}

}  // namespace
}  // namespace fins::test
