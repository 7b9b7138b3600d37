// The `fins` and `finsd` programs as a user runs them: output, JSON, exit codes
// (0 ok, 2 usage, 3 transport, 4 end code).
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

class Cli : public FinsdTest {};

TEST_F(Cli, WriteThenReadWordsHumanAndJson) {
    auto w = fins({"write", "D100", "1", "-2", "300", "--as", "int16"});
    EXPECT_EQ(w.exit_code, 0) << w.err;
    EXPECT_EQ(w.out, "wrote 3 words at D100\n");
    auto r = fins({"read", "D100", "3", "--as", "int16"}, true);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "D100  1\nD101  -2\nD102  300\n");
    auto j = fins({"read", "D100", "3", "--json"});
    ASSERT_EQ(j.exit_code, 0) << j.err;
    auto doc = nlohmann::json::parse(j.out);
    EXPECT_EQ(doc["address"], "D100");
    EXPECT_EQ(doc["values"], nlohmann::json::parse("[1, 65534, 300]"));
}

TEST_F(Cli, EveryValueFormatRoundTrips) {
    struct Case {
        const char* as;
        std::vector<std::string> values;
        std::string printed;
    };
    const Case cases[] = {
        {"uint16", {"65535"}, "D10  65535\n"},
        {"int32", {"-123456"}, "D10  -123456\n"},
        {"uint32", {"4000000000"}, "D10  4000000000\n"},
        {"float", {"1.5"}, "D10  1.5\n"},
        {"double", {"-0.25"}, "D10  -0.25\n"},
        {"bcd", {"1234"}, "D10  1234\n"},
        {"hex", {"0xBEEF"}, "D10  0xBEEF\n"},
        {"string", {"AB"}, "D10  \"AB\"\n"},
    };
    for (const auto& c : cases) {
        std::vector<std::string> args{"write", "D10"};
        args.insert(args.end(), c.values.begin(), c.values.end());
        args.insert(args.end(), {"--as", c.as});
        auto w = fins(args);
        ASSERT_EQ(w.exit_code, 0) << c.as << ": " << w.err;
        auto r = fins({"read", "D10", "1", "--as", c.as});
        EXPECT_EQ(r.exit_code, 0) << c.as << ": " << r.err;
        EXPECT_EQ(r.out, c.printed) << c.as;
    }
}

TEST_F(Cli, BitsFillTransferAndReadMulti) {
    EXPECT_EQ(fins({"write", "CIO10.13", "1", "0", "on"}).exit_code, 0);
    auto bits = fins({"read", "CIO10.13", "3"});
    EXPECT_EQ(bits.out, "CIO10.13  1\nCIO10.14  0\nCIO10.15  1\n");
    EXPECT_EQ(fins({"fill", "D0", "4", "0x00FF"}, true).exit_code, 0);
    EXPECT_EQ(fins({"transfer", "D0", "H0", "4"}).exit_code, 0);
    auto h = fins({"read", "H0", "4", "--as", "hex"});
    EXPECT_EQ(h.out, "H0  0x00FF\nH1  0x00FF\nH2  0x00FF\nH3  0x00FF\n");
    auto m = fins({"read-multi", "H0", "CIO10.13", "T5", "--json"});
    ASSERT_EQ(m.exit_code, 0) << m.err;
    auto doc = nlohmann::json::parse(m.out);
    EXPECT_EQ(doc["items"][0]["value"], 255);
    EXPECT_EQ(doc["items"][1]["value"], 1);
    EXPECT_EQ(doc["items"][2]["address"], "T5");
}

TEST_F(Cli, RawPrintsTheDecodedAnswer) {
    auto r = fins({"raw", "0101", "82 00 0A 00 00 02"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("end code 0000 normal completion"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("data (4 bytes): 00 00 00 00"), std::string::npos) << r.out;
    auto bad = fins({"raw", "0F01", "--json"});
    EXPECT_EQ(bad.exit_code, 4);
    auto doc = nlohmann::json::parse(bad.out);
    EXPECT_EQ(doc["end_code"], "0401");
    EXPECT_EQ(doc["name"], "undefined command");
}

TEST_F(Cli, ExitCodesSeparateUsageTransportAndEndCode) {
    auto usage = fins({"read", "Q100"});
    EXPECT_EQ(usage.exit_code, 2);
    EXPECT_NE(usage.err.find("bad address 'Q100'"), std::string::npos) << usage.err;
    EXPECT_EQ(fins({"read", "D100", "--as", "nonsense"}).exit_code, 2);
    EXPECT_EQ(fins({"write", "D100", "70000"}).exit_code, 2);
    EXPECT_EQ(fins({"nosuchverb"}).exit_code, 2);

    auto end_code = fins({"write", "A10", "1"});  // A000-A447 are read-only
    EXPECT_EQ(end_code.exit_code, 4);
    EXPECT_NE(end_code.err.find("2101"), std::string::npos) << end_code.err;
    auto json = fins({"write", "A10", "1", "--json"});
    EXPECT_EQ(nlohmann::json::parse(json.out)["error"]["end_code"], "2101");

    // Nobody listens on the port finsd's own port + 1 is unlikely to be; UDP times out.
    auto transport = run({fins_path, "--port", "1", "--timeout", "0.2", "read", "D0"});
    EXPECT_EQ(transport.exit_code, 3);
    auto tcp = run({fins_path, "--port", "1", "--tcp", "--timeout", "0.5", "read", "D0"});
    EXPECT_EQ(tcp.exit_code, 3);
    // Issue 7 item 3: a transport error names the endpoint.
    EXPECT_NE(tcp.err.find("127.0.0.1:1: "), std::string::npos) << tcp.err;
    EXPECT_NE(transport.err.find("127.0.0.1:1: "), std::string::npos) << transport.err;
}

// Issue 25: `fins read D0 2 --as string` over 41 E1 42 43 aborted (the JSON dump of the
// text threw). Each byte is the character of the same code point, printed as UTF-8.
TEST_F(Cli, StringBytesAbove7FPrintAsLatin1) {
    ASSERT_EQ(fins({"write", "D0", "0x41E1", "0x4243"}).exit_code, 0);
    auto r = fins({"read", "D0", "2", "--as", "string"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out,
              "D0  \"A\xC3\xA1"
              "BC\"\n");
    auto j = fins({"read", "D0", "2", "--as", "string", "--json"});
    ASSERT_EQ(j.exit_code, 0) << j.err;
    EXPECT_EQ(nlohmann::json::parse(j.out)["values"][0],
              "A\xC3\xA1"
              "BC");
    // The text writes back the same words; a character above U+00FF is refused.
    ASSERT_EQ(fins({"write", "D10",
                    "\xC2\xB0"
                    "C",
                    "--as", "string"})
                  .exit_code,
              0);
    EXPECT_EQ(fins({"read", "D10", "--as", "hex"}).out, "D10  0xB043\n");
    auto high = fins({"write", "D10", "\xE2\x82\xAC", "--as", "string"});  // euro sign
    EXPECT_EQ(high.exit_code, 2);
    EXPECT_NE(high.err.find("U+20AC, above U+00FF"), std::string::npos) << high.err;
    auto bad = fins({"write", "D10", "\xB0", "--as", "string", "--json"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(
        nlohmann::json::parse(bad.out)["error"]["message"].get<std::string>().find("not UTF-8"),
        std::string::npos)
        << bad.out;
    EXPECT_EQ(fins({"read", "D10", "--as", "hex"}).out, "D10  0xB043\n");
}

// A float the format cannot hold was written as +inf; "--5" was read as 5.
TEST_F(Cli, NumbersTheFormatCannotHoldAreRefused) {
    auto big = fins({"write", "D0", "3.5e38", "--as", "float"});
    EXPECT_EQ(big.exit_code, 2);
    EXPECT_NE(big.err.find("'3.5e38' is out of range for float"), std::string::npos) << big.err;
    auto huge = fins({"write", "D0", "1e309", "--as", "double"});
    EXPECT_EQ(huge.exit_code, 2);
    EXPECT_NE(huge.err.find("out of range for double"), std::string::npos) << huge.err;
    auto twice = fins({"write", "D0", "--", "--5"});
    EXPECT_EQ(twice.exit_code, 2);
    EXPECT_NE(twice.err.find("'--5' is not a valid uint16 value"), std::string::npos) << twice.err;
    EXPECT_EQ(fins({"write", "D0", "--5", "--as", "int16"}).exit_code, 2);
    EXPECT_EQ(fins({"read", "D0", "4", "--as", "hex"}).out,
              "D0  0x0000\nD1  0x0000\nD2  0x0000\nD3  0x0000\n");
}

TEST(Finsd, RefusesBadOptionsAndBusyPorts) {
    EXPECT_EQ(run({finsd_path, "--node", "0"}).exit_code, 2);
    EXPECT_EQ(run({finsd_path, "--bind", "not-an-ip", "--port", "0"}).exit_code, 3);
    Finsd first({}, {.log_level = "off"});
    ASSERT_TRUE(first.started()) << first.result().err;
    auto busy = run({finsd_path, "--port", std::to_string(first.port())});
    EXPECT_EQ(busy.exit_code, 3);
    EXPECT_NE(busy.err.find("cannot listen"), std::string::npos) << busy.err;
}

}  // namespace
}  // namespace fins::test
