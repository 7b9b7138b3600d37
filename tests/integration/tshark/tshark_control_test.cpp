// Conformance oracle for 04 01, 04 02, 05 01, 05 02, 06 20, 07 01, 07 02: Wireshark's
// FINS dissector decodes what our client and server exchange on loopback, flags none
// of it as malformed, and reads back the fields we meant (mode code, model, unit count,
// cycle time, clock fields, end codes).
//
// Wireshark's dissector follows the CV-series manual (W227). Four request variants
// that W342 allows trip it, and are sent last, over UDP only, to pin that knowledge:
//   04 01 and 05 01 without parameters  -> its parser throws ("Exception occurred")
//   04 02 FFFF                          -> "Unexpected Length (Should be 0)" (CV: none)
//   07 02 with 6 bytes                  -> "Unexpected Length" (it expects 5 or 7)
// The `fins` CLI sends the variants the dissector knows wherever W342 offers a choice
// (RUN with FFFF + mode, STOP without a program number, CLOCK WRITE with 7 bytes).
// Its 05 01 responses follow the CV-series layout too (2-byte remote I/O data: 161 and
// 69 bytes with the end code). finsd answers as W342 5-3-15 and real CS/CJ/CP units do,
// remote I/O "in a single byte" (160 and 68 bytes), so the dissector flags the full and
// the selector-01 answers "Unexpected Length" and decodes no field of them.
// Also, the dissector types the 40-byte "for system use" block of 05 01 as a string:
// DIP switch 00 followed by the largest EM bank (18 on a CJ2H) reads as "Trailing stray
// characters", a warning on the selector-00 responses only.
//
// Needs tshark and permission to capture on `lo`; skipped otherwise.
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fins/commands/clock.hpp"
#include "fins/commands/configuration.hpp"
#include "fins/commands/operating_mode.hpp"
#include "fins/commands/status.hpp"
#include "integration/support/process.hpp"
#include "integration/support/server_fixture.hpp"
#include "integration/tshark/tshark_support.hpp"

namespace fins::test {
namespace {

using tshark::severity_warning;
using tshark::split;

struct Row {
    std::string command, end_code, mode, model, units, parameter, average, year, malformed,
        severity, message;
};

const std::vector<std::string> fields{
    "omron.command",   "omron.response.code", "omron.mode_code",      "omron.controller.model",
    "omron.unit_nums", "omron.parameter",     "omron.avg_cycle_time", "omron.year",
    "_ws.malformed",   "_ws.expert.severity", "_ws.expert.message"};

std::vector<Row> parse_rows(const std::string& out) {
    std::vector<Row> rows;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);) {
        auto f = split(line, '|');
        if (f.size() != fields.size()) {
            ADD_FAILURE() << "unexpected tshark line: " << line;
            continue;
        }
        rows.push_back({f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8], f[9], f[10]});
    }
    return rows;
}

// Every exchange below must succeed; `what` names it in a failure.
template <class C>
void exchange(Client& c, const C& command, const char* what) {
    EXPECT_TRUE(c.send(command).has_value()) << what;
}

TEST(TsharkControl, DissectorReadsModeConfigurationCycleTimeAndClockTraffic) {
    ServerThread server;
    tshark::Capture capture(server.port(), "control");
    if (!capture.ready())
        GTEST_SKIP() << "tshark missing, or no permission to capture on lo (root or wireshark)";

    for (bool tcp : {false, true}) {
        auto c = server.client(tcp);
        ASSERT_NE(c, nullptr);
        exchange(*c, fins::Run{all_programs, RunMode::monitor}, "RUN FFFF 02");
        exchange(*c, fins::Run{all_programs, std::nullopt}, "RUN FFFF");
        exchange(*c, Stop{}, "STOP");
        exchange(*c, fins::Run{all_programs, RunMode::run}, "RUN FFFF 04");
        exchange(*c, CpuUnitDataRead{CpuUnitDataSection::model_and_area}, "05 01 00");
        exchange(*c, CpuUnitDataRead{CpuUnitDataSection::units_and_info}, "05 01 01");
        exchange(*c, ConnectionDataRead{0x00, std::nullopt}, "05 02 00");
        exchange(*c, ConnectionDataRead{0x10, 1}, "05 02 10 01");
        exchange(*c, CycleTimeRead{CycleTimeOperation::read}, "06 20 01");
        exchange(*c, CycleTimeRead{CycleTimeOperation::initialize}, "06 20 00");
        exchange(*c, ClockRead{}, "07 01");
        exchange(*c, ClockWrite{30, 1, 2, 3, 4, 5, 3}, "07 02 x 7");
        exchange(*c, ClockWrite{30, 1, 2, 3, 4, std::nullopt, std::nullopt}, "07 02 x 5");
        // End codes: 110C for a bad mode byte and a bad 06 20 parameter.
        const std::vector<std::uint8_t> bad_mode{0xFF, 0xFF, 0x03};
        const std::vector<std::uint8_t> bad_parameter{0x02};
        EXPECT_EQ(c->send_raw(fins::Run::code, bad_mode)->code.raw(), 0x110C);
        EXPECT_EQ(c->send_raw(CycleTimeRead::code, bad_parameter)->code.raw(), 0x110C);
    }
    {
        auto c = server.client(false);
        ASSERT_NE(c, nullptr);
        exchange(*c, CpuUnitDataRead{}, "05 01 (all)");
        exchange(*c, fins::Run{}, "RUN (code only)");
        exchange(*c, Stop{all_programs}, "STOP FFFF");
        exchange(*c, ClockWrite{30, 1, 2, 3, 4, 5, std::nullopt}, "07 02 x 6");
    }
    for (bool tcp : {false, true}) {  // end marker: 0F 01 (0401) on both transports
        auto c = server.client(tcp);
        ASSERT_NE(c, nullptr);
        EXPECT_TRUE(c->send_raw({0x0F, 0x01}, {}).has_value());
    }
    // Read the growing capture (bounded) until the 4 marker frames are in it.
    const RunResult decoded = capture.read_until(
        fields, [](const RunResult& d) { return tshark::count_rows(d, 0, "0x0f01") == 4; });
    const std::vector<Row> rows = parse_rows(decoded.out);
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    SCOPED_TRACE("tshark fields:\n" + decoded.out + decoded.err);

    std::map<std::string, int> commands, end_codes, modes, malformed;
    int stray = 0;
    int one_byte_remote_io = 0;  // 05 01 answers the CV-series dissector finds short
    for (const auto& r : rows) {
        ++commands[r.command];
        if (!r.end_code.empty()) ++end_codes[r.end_code];
        if (!r.mode.empty()) ++modes[r.mode];
        if (!r.malformed.empty()) ++malformed[r.command];
        // (It reads no end code from them either.)
        if (r.command == "0x0501" && !r.malformed.empty() && r.message == "Unexpected Length")
            ++one_byte_remote_io;
        if (r.command == "0x0f01" || !r.malformed.empty()) continue;
        if (r.message == "Trailing stray characters") {
            ++stray;
            EXPECT_EQ(r.command, "0x0501");
            continue;
        }
        for (const auto& s : split(r.severity, ','))
            if (!s.empty()) {
                EXPECT_LT(std::stol(s), severity_warning) << r.command << r.message;
            }
    }
    // Malformed: exactly the four dissector-limited requests and the three 05 01 answers
    // with a one-byte remote I/O field (selector 01 on each transport, all over UDP).
    EXPECT_EQ(malformed, (std::map<std::string, int>{
                             {"0x0401", 1}, {"0x0402", 1}, {"0x0501", 1 + 3}, {"0x0702", 1}}));
    EXPECT_EQ(one_byte_remote_io, 2 + 1);
    // Each exchange crossed as request + response.
    EXPECT_EQ(commands["0x0401"], 2 * 2 * 4 + 2);
    EXPECT_EQ(commands["0x0402"], 2 * 2 + 2);
    EXPECT_EQ(commands["0x0501"], 2 * 2 * 2 + 2);
    EXPECT_EQ(commands["0x0502"], 2 * 2 * 2);
    EXPECT_EQ(commands["0x0620"], 2 * 2 * 3);
    EXPECT_EQ(commands["0x0701"], 2 * 2);
    EXPECT_EQ(commands["0x0702"], 2 * 2 * 2 + 2);
    EXPECT_EQ(modes["0x02"], 2);  // RUN FFFF 02 on each transport
    EXPECT_EQ(modes["0x04"], 2);  // RUN FFFF 04
    EXPECT_EQ(modes["0x03"], 2);  // the refused mode byte
    EXPECT_EQ(end_codes["0x110c"], 2 * 2);
    // Model of the CPU Unit in the 05 01 responses it decodes (selector 00): 2.
    int models = 0;
    int unit_counts = 0;
    int averages = 0;
    int years = 0;
    for (const auto& r : rows) {
        if (!r.model.empty() && r.model.rfind(plc::cj2h().model, 0) == 0) ++models;
        if (!r.units.empty()) ++unit_counts;
        if (!r.average.empty()) ++averages;
        // CLOCK WRITE requests: BCD 30 for 2030, which the dissector prints as 48 (0x30).
        if (r.command == "0x0702" && r.end_code.empty() && r.year == "48") ++years;
    }
    EXPECT_EQ(models, 2);
    EXPECT_EQ(stray, models);
    EXPECT_EQ(unit_counts, 2 * 1 + 2 * 2);  // the requests with a count + every response
    EXPECT_EQ(averages, 2);
    EXPECT_EQ(years, 2 * 2 + 1);
}

}  // namespace
}  // namespace fins::test
