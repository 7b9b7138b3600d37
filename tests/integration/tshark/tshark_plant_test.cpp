// tshark decodes the frames a plant relays (README "A plant of several networks"): the
// two-plant setup of plant_test.cpp puts the relayed command (GCT decremented, SNA 00
// made network 1) and its answer on the wire between router-b and line-3, and a relay
// error (end code bit 15 and the relay word) goes back to the client. None of it may be
// flagged malformed.
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include "fins/address.hpp"
#include "integration/support/plant_fixture.hpp"
#include "integration/tshark/tshark_support.hpp"

namespace fins::test {
namespace {

TEST(TsharkPlant, RelayedFramesAndRelayErrorsDecodeWithoutMalformedFlag) {
    constexpr std::uint16_t port = 29663;
    const auto [routers, line] = routers_and_line(port);
    PlantThread a(routers);
    PlantThread b(line);
    tshark::Capture capture(port, "plant");
    if (!capture.ready())
        GTEST_SKIP() << "tshark missing, or no permission to capture on lo (root or wireshark)";

    ClientOptions o;
    o.source = {0, 77, 0};
    auto c = a.client("127.0.1.1", port, {3, 5, 0}, false, o);
    ASSERT_TRUE(c->read_words(*parse_address("D0"), 4));
    auto lost = a.client("127.0.1.1", port, {9, 5, 0}, false, o);
    const auto relay_error =
        lost->send_raw({0x01, 0x01}, std::vector<std::uint8_t>{0x82, 0, 0, 0, 0, 1});
    ASSERT_TRUE(relay_error);
    ASSERT_EQ(relay_error->code.raw(), 0x8501);

    const std::vector<std::string> fields{"omron.gct", "omron.dna",           "omron.da1",
                                          "omron.sna", "omron.sa1",           "omron.command",
                                          "omron.icf", "omron.response.code", "_ws.malformed"};
    const auto decoded = capture.read_until(
        fields, [](const RunResult& d) { return d.out.find("0x8501") != std::string::npos; });
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    SCOPED_TRACE("tshark fields:\n" + decoded.out + decoded.err);
    int relayed_commands = 0, relay_errors = 0;
    std::istringstream lines(decoded.out);
    for (std::string line_text; std::getline(lines, line_text);) {
        const auto f = tshark::split(line_text, '|');
        ASSERT_EQ(f.size(), fields.size()) << line_text;
        EXPECT_TRUE(f[8].empty()) << "malformed: " << line_text;
        // Between router-b and line-3: DNA 3, DA1 5, SNA 1 (was 00), GCT 00 (02 - 2).
        if (f[1] == "0x03" && f[2] == "0x05" && f[3] == "0x01" && f[0] == "0x00")
            ++relayed_commands;
        if (f[7] == "0x8501") ++relay_errors;
    }
    EXPECT_GE(relayed_commands, 1);
    EXPECT_EQ(relay_errors, 1);
}

}  // namespace
}  // namespace fins::test
