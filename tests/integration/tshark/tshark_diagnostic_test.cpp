// Conformance oracle for the diagnostic commands: Wireshark's FINS dissector decodes
// 06 01, 09 20 (read / clear / FAL read), 0C 01 .. 0C 03, 21 01 .. 21 03, 21 40 / 21 41
// and 23 01 / 23 02 as our client and server exchange them over UDP and TCP. Nothing
// may be flagged malformed, and the fields it reads back must be the ones we sent.
// 21 40 / 21 41 are CS/CJ-only codes the dissector (written from the CV manual) does
// not know: they may carry its "Unknown Command-Code" warning and nothing worse.
//
// Needs tshark and permission to capture on `lo` (skipped otherwise, with the reason).
#include <unistd.h>

#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration/support/process.hpp"
#include "integration/support/server_fixture.hpp"
#include "integration/tshark/tshark_support.hpp"

namespace fins::test {
namespace {

using tshark::severity_warning;
using tshark::split;

// Fields, in output order.
const std::vector<std::string> fields = {"omron.command",
                                         "omron.response.code",
                                         "_ws.malformed",
                                         "_ws.expert.severity",
                                         "omron.status",
                                         "omron.error_message",
                                         "omron.fals",
                                         "omron.error_reset_fals_no",
                                         "omron.no_stored_records",
                                         "omron.number_of_bits_flags",
                                         "omron.set_reset_specification",
                                         "omron.bit_flag",
                                         "omron.program_number",
                                         "omron.message"};

using Row = std::map<std::string, std::string>;

// One map of field -> value per frame.
std::vector<Row> parse_rows(const RunResult& result) {
    std::vector<Row> rows;
    std::istringstream lines(result.out);
    for (std::string line; std::getline(lines, line);) {
        const auto values = split(line, '|');
        if (values.size() != fields.size()) continue;
        Row row;
        for (std::size_t i = 0; i < fields.size(); ++i)
            row[fields[i]] = values[i];
        rows.push_back(row);
    }
    return rows;
}

// MRC SRC + parameters, sent raw so the bytes are exactly the manual's.
struct Exchange {
    CommandCode code;
    std::vector<std::uint8_t> parameters;
};

const std::vector<Exchange> traffic = {
    {{0x06, 0x01}, {}},
    {{0x09, 0x20}, {0x00, 0xFF}},  // MESSAGE READ all
    {{0x09, 0x20}, {0x40, 0x01}},  // MESSAGE CLEAR MSG 0
    {{0x09, 0x20}, {0x80, 0x05}},  // FAL/FALS READ 5
    {{0x0C, 0x01}, {0xFF, 0xFF}},
    {{0x0C, 0x02}, {0xFF, 0xFF}},
    {{0x0C, 0x03}, {0xFF, 0xFF}},
    {{0x0C, 0x01}, {0x00, 0x00}},  // 1106
    {{0x21, 0x01}, {0xFF, 0xFE}},
    {{0x21, 0x02}, {0x00, 0x00, 0x00, 0x14}},  // empty log: 1104 with the header
    {{0x21, 0x03}, {}},
    {{0x21, 0x40}, {0x00, 0x00, 0x00, 0x14}},
    {{0x21, 0x41}, {}},
    {{0x04, 0x02}, {}},  // STOP: forcing is refused in RUN mode
    {{0x23, 0x01}, {0x00, 0x01, 0x00, 0x01, 0x30, 0x00, 0x0A, 0x0D}},
    {{0x23, 0x02}, {}},
    {{0x04, 0x01}, {0xFF, 0xFF}},  // back to MONITOR for the next transport
};

TEST(TsharkDiagnostic, DissectorReadsOurDiagnosticTrafficWithoutComplaint) {
    ServerThread server;
    tshark::Capture capture(server.port(), "diagnostic");
    if (!capture.ready())
        GTEST_SKIP() << "tshark missing, or no permission to capture on lo (root or wireshark)";

    for (bool tcp : {false, true}) {
        auto c = server.client(tcp);
        ASSERT_NE(c, nullptr);
        for (const auto& e : traffic) {
            auto r = c->send_raw(e.code, e.parameters);
            ASSERT_TRUE(r.has_value()) << std::hex << e.code.value();
        }
        ASSERT_TRUE(c->send_raw({0x0F, 0x01}, {}).has_value());  // end marker
    }
    // Read the growing capture (bounded) until both end markers are in it.
    const RunResult decoded = capture.read_until(
        fields, [](const RunResult& d) { return tshark::count_rows(d, 0, "0x0f01") == 4; });
    const std::vector<Row> rows = parse_rows(decoded);
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    SCOPED_TRACE("tshark fields:\n" + decoded.out + decoded.err);

    std::map<std::string, int> commands;
    std::map<std::string, int> seen;  // "command field=value"
    for (const auto& r : rows) {
        const auto& command = r.at("omron.command");
        EXPECT_TRUE(r.at("_ws.malformed").empty()) << "malformed: " << command;
        ++commands[command];
        for (const auto& [field, value] : r) {
            if (!value.empty() && field != "omron.command")
                ++seen[command + " " + field + "=" + value];
        }
        if (command == "0x0f01" || command == "0x2140" || command == "0x2141") continue;
        for (const auto& s : split(r.at("_ws.expert.severity"), ',')) {
            if (!s.empty()) {
                EXPECT_LT(std::stol(s), severity_warning) << command;
            }
        }
    }
    for (const char* c : {"0x0601", "0x0c02", "0x0c03", "0x2101", "0x2102", "0x2103", "0x2140",
                          "0x2141", "0x2301", "0x2302"})
        EXPECT_EQ(commands[c], 2 * 2) << c;  // request + response, two transports
    EXPECT_EQ(commands["0x0920"], 3 * 2 * 2);
    EXPECT_EQ(commands["0x0c01"], 2 * 2 * 2);
    // What the dissector read back.
    EXPECT_EQ(seen["0x0601 omron.status=0x05"], 2);  // running, battery present
    EXPECT_EQ(seen["0x0601 omron.error_message=                "], 2);
    EXPECT_EQ(seen["0x0920 omron.message=0x00ff"], 4);  // read: request and echo
    EXPECT_EQ(seen["0x0920 omron.message=0x4001"], 2);  // clear
    EXPECT_EQ(seen["0x0920 omron.fals=0x0005"], 4);     // FAL read: request and answer
    EXPECT_EQ(seen["0x0c01 omron.program_number=0xffff"], 2);
    EXPECT_EQ(seen["0x0c01 omron.response.code=0x1106"], 2);
    EXPECT_EQ(seen["0x2101 omron.error_reset_fals_no=0xfffe"], 2);
    EXPECT_EQ(seen["0x2102 omron.response.code=0x1104"], 2);
    EXPECT_EQ(seen["0x2102 omron.no_stored_records=0"], 2);
    EXPECT_EQ(seen["0x2301 omron.number_of_bits_flags=1"], 2);
    EXPECT_EQ(seen["0x2301 omron.set_reset_specification=0x0001"], 2);
    EXPECT_EQ(seen["0x2301 omron.bit_flag=2573"], 2);  // 00 0A 0D: CIO 10 bit 13
    EXPECT_EQ(seen["0x2301 omron.response.code=0x0000"], 2);
    EXPECT_EQ(seen["0x2302 omron.response.code=0x0000"], 2);
}

}  // namespace
}  // namespace fins::test
