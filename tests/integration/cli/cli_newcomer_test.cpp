// fins and finsd as a newcomer meets them (issue 7 items 6-9, 11): local mistakes are
// usage errors with true messages, a PLC on another node explains itself, the common
// conventions (--version, help, prefixes, stdout/stderr), safe examples, typed initial
// memory, CPU error flags on reads and progress on a terminal.
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"
#include "integration/support/process.hpp"

namespace fins::test {
namespace {

const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";

RunResult fins(const Finsd& d, std::vector<std::string> args) {
    std::vector<std::string> argv{fins_bin, "--port", std::to_string(d.port()), "--timeout", "3"};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

nlohmann::json error_of(const RunResult& r) {
    auto doc = nlohmann::json::parse(r.out, nullptr, false);
    return doc.is_object() && doc.contains("error") ? doc["error"] : nlohmann::json{};
}

TEST(CliErrors, LocalDecodeAndRangeMistakesAreUsageErrorsWithTrueMessages) {
    Finsd d({});
    ASSERT_TRUE(d.started()) << d.result().err;
    ASSERT_EQ(fins(d, {"write", "D100", "0x12AB"}).exit_code, 0);

    auto bcd = fins(d, {"--json", "read", "D100", "--as", "bcd"});
    EXPECT_EQ(bcd.exit_code, 2) << bcd.err;
    EXPECT_EQ(error_of(bcd)["kind"], "usage");
    EXPECT_NE(bcd.err.find("fins: D100 holds 0x12AB, which is not BCD"), std::string::npos)
        << bcd.err;

    auto bits = fins(d, {"--json", "read", "D100", "--as", "bits"});
    EXPECT_EQ(bits.exit_code, 2) << bits.err;
    EXPECT_EQ(error_of(bits)["kind"], "usage");
    EXPECT_EQ(bits.err.find("only bit access"), std::string::npos) << bits.err;
    EXPECT_NE(bits.err.find("D100 is a word: name a bit (D100.00)"), std::string::npos) << bits.err;

    // TK has only bit access: it reads as bits without --as.
    auto task = fins(d, {"read", "TK2"});
    EXPECT_EQ(task.exit_code, 0) << task.err;
    EXPECT_EQ(task.out, "TK2  0\n");

    // Index registers are 32-bit: two registers are two values, not four words.
    auto ir = fins(d, {"read", "IR0", "2", "--as", "hex"});
    EXPECT_EQ(ir.exit_code, 0) << ir.err;
    EXPECT_EQ(ir.out, "IR0  0x00000000\nIR1  0x00000000\n");
    auto ir_write = fins(d, {"write", "IR0", "5"});
    EXPECT_EQ(ir_write.exit_code, 2);
    EXPECT_NE(ir_write.err.find("32-bit index register"), std::string::npos) << ir_write.err;

    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"read", "D30000", "40000"},
          std::vector<std::string>{"fill", "D32000", "1000", "1"},
          std::vector<std::string>{"transfer", "D32000", "D0", "1000"},
          std::vector<std::string>{"transfer", "D0", "D32000", "1000"},
          std::vector<std::string>{"write", "D32767", "1", "2"}}) {
        auto a = args;
        a.insert(a.begin(), "--json");
        auto r = fins(d, a);
        EXPECT_EQ(r.exit_code, 2) << args[0] << " " << args[1] << ": " << r.err;
        EXPECT_EQ(error_of(r)["kind"], "usage") << r.out;
        EXPECT_NE(r.err.find("the last word of the area"), std::string::npos) << r.err;
    }
    // Inside the 5-2-2 area but past what the profile has: the PLC's own 1104.
    Finsd cj1m({"--profile", "cj1m"});
    ASSERT_TRUE(cj1m.started()) << cj1m.result().err;
    auto em = fins(cj1m, {"read", "E0_0"});
    EXPECT_EQ(em.exit_code, 4) << em.err;
}

TEST(CliNode, PlainUdpToAnotherNodeNamesTheDestToUse) {
    Finsd d({"--node", "10"});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto plain = fins(d, {"read", "D0"});
    EXPECT_EQ(plain.exit_code, 4) << plain.err;
    EXPECT_NE(plain.err.find("fins: the PLC at 127.0.0.1:" + std::to_string(d.port()) +
                             " is node 10: use --dest 0.10.0"),
              std::string::npos)
        << plain.err;
    auto json = fins(d, {"--json", "read", "D0"});
    EXPECT_EQ(error_of(json)["end_code"], "0201");
    EXPECT_EQ(error_of(json)["hint"], "the PLC at 127.0.0.1:" + std::to_string(d.port()) +
                                          " is node 10: use --dest 0.10.0");

    auto fixed = fins(d, {"--dest", "0.10.0", "read", "D0"});
    EXPECT_EQ(fixed.exit_code, 0) << fixed.err;

    auto probe = fins(d, {"probe"});
    EXPECT_EQ(probe.exit_code, 0) << probe.err;
    EXPECT_NE(probe.out.find("FINS node 0.10.0, CJ2H-CPU68-EIP"), std::string::npos) << probe.out;
    EXPECT_NE(probe.out.find("add --dest 0.10.0"), std::string::npos) << probe.out;
    auto probe_json = fins(d, {"probe", "--json", "--tcp"});
    auto doc = nlohmann::json::parse(probe_json.out, nullptr, false);
    EXPECT_EQ(doc["node"], "0.10.0") << probe_json.out;
    EXPECT_EQ(doc["protocol"], "tcp");
}

TEST(CliNode, DestUnitsAcceptHex) {
    Finsd d({"--profile", "cs1h-lcb", "--node", "12"});
    ASSERT_TRUE(d.started()) << d.result().err;
    // E1 is the Loop Control Board: 02 40 is its command, so the unit was parsed as 0xE1.
    auto hex = fins(d, {"--dest", "0.12.E1", "raw", "0240", "0001 0001 0006"});
    EXPECT_EQ(hex.exit_code, 0) << hex.out << hex.err;
    auto prefixed = fins(d, {"--dest", "0.12.0xE1", "raw", "0240", "0001 0001 0006"});
    EXPECT_EQ(prefixed.exit_code, 0) << prefixed.out << prefixed.err;
    auto bad = fins(d, {"--dest", "0.12.G1", "read", "D0"});
    EXPECT_EQ(bad.exit_code, 2);
}

TEST(CliConventions, VersionHelpPrefixesAndPlurals) {
    const std::regex version(R"((fins|finsd) \d+\.\d+\.\d+\n)");
    auto v = run({fins_bin, "--version"});
    EXPECT_EQ(v.exit_code, 0);
    EXPECT_TRUE(std::regex_match(v.out, version)) << v.out;
    auto dv = run({finsd_path, "--version"});
    EXPECT_EQ(dv.exit_code, 0);
    EXPECT_TRUE(std::regex_match(dv.out, version)) << dv.out;
    EXPECT_EQ(v.out.substr(v.out.find(' ')), dv.out.substr(dv.out.find(' ')));

    for (const char* verb : {"read", "param-read", "status", "clock", "probe"}) {
        auto h = run({fins_bin, verb, "--help"});
        EXPECT_EQ(h.exit_code, 0) << verb;
        EXPECT_NE(h.out.find("--host"), std::string::npos) << verb << ": " << h.out;
        EXPECT_NE(h.out.find("--json"), std::string::npos) << verb;
    }
    auto dh = run({finsd_path, "--help"});
    EXPECT_NE(dh.out.find("finsd ctl"), std::string::npos) << dh.out;

    auto parse = run({fins_bin, "read", "D0", "--bogus"});
    EXPECT_EQ(parse.exit_code, 2);
    EXPECT_EQ(parse.err.rfind("fins: ", 0), 0u) << parse.err;
    auto parse_json = run({fins_bin, "--json", "read"});
    EXPECT_EQ(parse_json.exit_code, 2);
    EXPECT_EQ(parse_json.err.rfind("fins: ", 0), 0u) << parse_json.err;
    EXPECT_EQ(error_of(parse_json)["kind"], "usage") << parse_json.out;
    auto finsd_parse = run({finsd_path, "--bogus"});
    EXPECT_EQ(finsd_parse.exit_code, 2);
    EXPECT_EQ(finsd_parse.err.rfind("finsd: ", 0), 0u) << finsd_parse.err;

    Finsd d({});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_EQ(fins(d, {"write", "D0", "7"}).out, "wrote 1 word at D0\n");
    EXPECT_EQ(fins(d, {"write", "D0", "7", "8"}).out, "wrote 2 words at D0\n");
    EXPECT_EQ(fins(d, {"write", "CIO0.0", "1"}).out, "wrote 1 bit at CIO0.00\n");
    EXPECT_EQ(fins(d, {"fill", "D0", "1", "0"}).out, "filled 1 word at D0 with 0x0000\n");
    EXPECT_EQ(fins(d, {"transfer", "D0", "D1", "1"}).out, "copied 1 word from D0 to D1\n");
}

TEST(CliConventions, FinsdStdoutCarriesOnlyListeningAndCtlTakesOptionsAfterTheVerb) {
    ScratchDir dir("conventions");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--control", socket}, {.log_level = "info"});
    ASSERT_TRUE(d.started()) << d.result().out << d.result().err;  // "listening" came first
    EXPECT_TRUE(d.child().wait_for_stderr("FINS address"));        // the start-up log is on stderr

    auto after = run({finsd_path, "ctl", "status", "--socket", socket});
    EXPECT_EQ(after.exit_code, 0) << after.err;
    auto before = run({finsd_path, "ctl", "--socket", socket, "status"});
    EXPECT_EQ(before.exit_code, 0) << before.err;
    // No --socket: $FINSD_SOCKET (or the default path), the same rule finsd follows.
    auto from_env = run({"/usr/bin/env", "FINSD_SOCKET=" + socket, finsd_path, "ctl", "status"});
    EXPECT_EQ(from_env.exit_code, 0) << from_env.err;
    auto missing =
        run({"/usr/bin/env", "FINSD_SOCKET=" + socket + ".none", finsd_path, "ctl", "status"});
    EXPECT_EQ(missing.exit_code, 3);
    EXPECT_EQ(missing.err.rfind("finsd ctl: ", 0), 0u) << missing.err;

    auto r = d.stop();
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_EQ(r.out, "") << "after the listening line stdout must stay empty";
}

TEST(CliSafety, ExamplesBindLoopbackAndProtectNodeNeedsAMode) {
    for (const auto& entry :
         std::filesystem::directory_iterator(std::string(FINS_SOURCE_DIR) + "/examples")) {
        std::ifstream f(entry.path());
        std::stringstream text;
        text << f.rdbuf();
        EXPECT_EQ(text.str().find("bind = \"0.0.0.0\""), std::string::npos) << entry.path();
    }
    auto off = run({finsd_path, "--port", "0", "--protect-node", "0.5"});
    EXPECT_EQ(off.exit_code, 2);
    EXPECT_NE(off.err.find("--protect-node has no effect"), std::string::npos) << off.err;
    Finsd listed({"--network-write-protection", "listed", "--protect-node", "0.5"});
    EXPECT_TRUE(listed.started()) << listed.result().err;
}

TEST(CliSafety, ForeignStateFileNamesBothProfiles) {
    ScratchDir dir("foreign");
    const std::string data = (dir.path() / "new" / "dir").string();  // created when missing
    {
        Finsd first({"--profile", "cs1h", "--data-dir", data});
        ASSERT_TRUE(first.started()) << first.result().err;
        ASSERT_TRUE(std::filesystem::exists(data + "/finsd.state"));
        first.stop();
    }
    Finsd second({"--profile", "cj2h", "--data-dir", data});
    EXPECT_FALSE(second.started());
    EXPECT_EQ(second.result().exit_code, 3);
    EXPECT_NE(second.result().err.find("the file is for profile 'cs1h', this finsd runs 'cj2h'"),
              std::string::npos)
        << second.result().err;
}

TEST(CliMemory, TypedInitialValues) {
    ScratchDir dir("typed");
    const auto config = dir.write("typed.toml", R"([memory]
"D200" = { float = 1.5 }
"D210" = { int32 = [-5, 70000] }
"D220" = { string = "HELLO" }
"D230" = { bcd = 1234 }
"D240" = { double = 2.25 }
"D250" = { uint32 = 4000000000 }
)");
    Finsd d({"--config", config});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_EQ(fins(d, {"read", "D200", "--as", "float"}).out, "D200  1.5\n");
    EXPECT_EQ(fins(d, {"read", "D210", "2", "--as", "int32"}).out, "D210  -5\nD212  70000\n");
    EXPECT_EQ(fins(d, {"read", "D220", "3", "--as", "string"}).out, "D220  \"HELLO\"\n");
    EXPECT_EQ(fins(d, {"read", "D230", "--as", "hex"}).out, "D230  0x1234\n");
    EXPECT_EQ(fins(d, {"read", "D240", "--as", "double"}).out, "D240  2.25\n");
    EXPECT_EQ(fins(d, {"read", "D250", "--as", "uint32"}).out, "D250  4000000000\n");

    const auto bad = dir.write("bad.toml", "[memory]\n\"D0\" = { flaot = 1 }\n");
    auto r = run({finsd_path, "--port", "0", "--config", bad});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("'flaot' is not a value type"), std::string::npos) << r.err;
    const auto range = dir.write("range.toml", "[memory]\n\"D0\" = { bcd = 12345 }\n");
    r = run({finsd_path, "--port", "0", "--config", range});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("memory.\"D0\".bcd: 12345 is out of range for bcd (0 to 9999)"),
              std::string::npos)
        << r.err;
}

TEST(CliReads, W342_5_1_3_ReadsShowTheCpuErrorFlags) {
    ScratchDir dir("flags");
    const auto config = dir.write("battery.toml", "[inject]\nbattery_error = true\n");
    Finsd d({"--config", config});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto text = fins(d, {"read", "D0"});
    EXPECT_EQ(text.exit_code, 0) << text.err;
    EXPECT_EQ(text.out, "D0  0\n");
    EXPECT_NE(text.err.find("non-fatal CPU error flag (0040)"), std::string::npos) << text.err;
    auto json = nlohmann::json::parse(fins(d, {"--json", "read-multi", "D0", "W0"}).out);
    EXPECT_EQ(json["non_fatal_cpu_error"], true);
    EXPECT_EQ(json["fatal_cpu_error"], false);

    Finsd clean({});
    ASSERT_TRUE(clean.started());
    auto quiet = fins(clean, {"--json", "read", "D0"});
    EXPECT_EQ(quiet.err, "");
    EXPECT_EQ(nlohmann::json::parse(quiet.out)["non_fatal_cpu_error"], false);
}

// Runs fins with stderr on a pseudo-terminal and returns what the terminal showed.
std::string run_on_terminal(const std::vector<std::string>& argv) {
    const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) return {};
    const std::string slave_name = ::ptsname(master);
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int slave = ::open(slave_name.c_str(), O_RDWR | O_NOCTTY);
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1);
        ::dup2(slave, 2);
        std::vector<char*> args;
        for (const auto& a : argv)
            args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        ::execv(args[0], args.data());
        ::_exit(127);
    }
    std::string seen;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
        pollfd p{master, POLLIN, 0};
        if (::poll(&p, 1, 100) > 0) {
            char buf[4096];
            const auto n = ::read(master, buf, sizeof buf);
            if (n > 0) seen.append(buf, static_cast<std::size_t>(n));
        }
        if (::waitpid(pid, &status, WNOHANG) == pid) {
            pollfd q{master, POLLIN, 0};
            while (::poll(&q, 1, 0) > 0) {  // drain what is left
                char buf[4096];
                const auto n = ::read(master, buf, sizeof buf);
                if (n <= 0) break;
                seen.append(buf, static_cast<std::size_t>(n));
            }
            ::close(master);
            return seen;
        }
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    ::close(master);
    return seen;
}

TEST(CliProgress, LongTransfersShowProgressOnATerminalOnly) {
    Finsd d({});
    ASSERT_TRUE(d.started()) << d.result().err;
    const std::vector<std::string> argv{fins_bin, "--port", std::to_string(d.port()),
                                        "read",   "D0",     "3000"};
    const auto shown = run_on_terminal(argv);
    EXPECT_NE(shown.find("read D0: 999/3000 words (33%)"), std::string::npos) << shown;
    EXPECT_NE(shown.find("\x1b[K"), std::string::npos) << "the line is erased at the end";
    auto piped = run(argv);  // stderr is a pipe: nothing but the values
    EXPECT_EQ(piped.exit_code, 0);
    EXPECT_EQ(piped.err, "");
}

}  // namespace
}  // namespace fins::test
