// `fins` as a new user meets it following the README (issue 18): true transport errors
// from probe, hints that work when followed, typos answered with the nearest verb, the
// area names of CX-Programmer, the source node write protection sees, NET.NODE
// destinations, messages that print what is there, and FINS_HOST / FINS_PORT.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"
#include "integration/support/process.hpp"

namespace fins::test {
namespace {

const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";

RunResult fins(std::uint16_t port, std::vector<std::string> args) {
    std::vector<std::string> argv{fins_bin, "--port", std::to_string(port), "--timeout", "3"};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}
RunResult fins(const Finsd& d, std::vector<std::string> args) {
    return fins(d.port(), std::move(args));
}

// `fins` with environment variables set (env(1) passes the rest of the environment on).
RunResult fins_env(std::vector<std::string> env, std::vector<std::string> args) {
    std::vector<std::string> argv{"/usr/bin/env"};
    argv.insert(argv.end(), env.begin(), env.end());
    argv.push_back(fins_bin);
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

bool has(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// A loopback port nothing listens on (bound, read and released: the kernel does not hand
// it out again at once).
std::uint16_t free_port(int type) {
    const int fd = ::socket(AF_INET, type, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t size = sizeof a;
    EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    EXPECT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &size), 0);
    ::close(fd);
    return ntohs(a.sin_port);
}

TEST(CliFirstUse, ProbeWithNothingListeningSaysWhatReadSays) {
    const auto udp = free_port(SOCK_DGRAM);
    auto read = fins(udp, {"read", "D0"});
    auto probe = fins(udp, {"probe"});
    EXPECT_EQ(read.exit_code, 3) << read.err;
    EXPECT_EQ(probe.exit_code, 3) << probe.err;
    EXPECT_TRUE(has(probe.err, "onnection refused")) << probe.err;
    EXPECT_FALSE(has(probe.err, "timeout")) << probe.err;
    // UDP connects nothing: a host that does not resolve is not "cannot connect".
    auto unresolved = run({fins_bin, "--host", "::1%nosuchif", "read", "D0"});
    EXPECT_EQ(unresolved.exit_code, 3) << unresolved.err;
    EXPECT_FALSE(has(unresolved.err, "cannot connect")) << unresolved.err;
    EXPECT_TRUE(has(unresolved.err, "fins: cannot send over UDP (nothing was sent): "))
        << unresolved.err;

    const auto tcp = free_port(SOCK_STREAM);
    auto tcp_probe = fins(tcp, {"--tcp", "probe"});
    EXPECT_EQ(tcp_probe.exit_code, 3) << tcp_probe.err;
    EXPECT_TRUE(has(tcp_probe.err, "onnection refused")) << tcp_probe.err;
    EXPECT_FALSE(has(tcp_probe.err, "timeout")) << tcp_probe.err;
}

// CS LCB manual 6-3 (02 40): the hint names the Inner Board, and the board's own 1101
// ("an unregistered function block") is not told in memory-area words.
TEST(CliFirstUse, LoopReadHintNamesTheInnerBoardUnitPerLcb6_3) {
    Finsd d({"--profile", "cs1h-lcb", "--node", "12"});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto plain = fins(d, {"loop-read", "1", "1"});
    EXPECT_EQ(plain.exit_code, 4) << plain.err;
    EXPECT_TRUE(has(plain.err, "use --dest 0.12.E1\n")) << plain.err;
    auto hinted = fins(d, {"--dest", "0.12.E1", "loop-read", "1", "6"});
    EXPECT_EQ(hinted.exit_code, 0) << hinted.err;

    auto unregistered = fins(d, {"--json", "--dest", "0.12.E1", "loop-read", "998", "1"});
    EXPECT_EQ(unregistered.exit_code, 4) << unregistered.err;
    EXPECT_TRUE(has(unregistered.err, "block 998 is not a registered function block"))
        << unregistered.err;
    EXPECT_FALSE(has(unregistered.err, "memory area")) << unregistered.err;
}

TEST(CliFirstUse, TyposNameTheNearestVerbAndGroupsListTheirVerbs) {
    auto reed = run({fins_bin, "reed", "D0"});
    EXPECT_EQ(reed.exit_code, 2);
    EXPECT_EQ(reed.err, "fins: unknown verb 'reed': did you mean read? (see fins --help)\n");
    auto swapped = run({fins_bin, "--json", "porbe"});
    EXPECT_EQ(swapped.exit_code, 2);
    EXPECT_TRUE(has(swapped.err, "did you mean probe?")) << swapped.err;
    EXPECT_TRUE(has(swapped.out, "\"kind\":\"usage\"")) << swapped.out;
    auto nothing_near = run({fins_bin, "xyzzy"});
    EXPECT_EQ(nothing_near.exit_code, 2);
    EXPECT_TRUE(has(nothing_near.err, "the verbs are: read, write,")) << nothing_near.err;

    auto files = run({fins_bin, "files"});
    EXPECT_EQ(files.exit_code, 2);
    EXPECT_TRUE(has(files.err, "fins: 'fins files' needs a verb: ls, get, put,")) << files.err;
    EXPECT_FALSE(has(files.err, "A subcommand is required")) << files.err;
    auto lss = run({fins_bin, "files", "lss"});
    EXPECT_EQ(lss.exit_code, 2);
    EXPECT_TRUE(has(lss.err, "'fins files' has no verb 'lss': did you mean ls?")) << lss.err;
    auto bare = run({fins_bin});
    EXPECT_EQ(bare.exit_code, 2);
    EXPECT_TRUE(has(bare.err, "'fins' needs a verb: read, write,")) << bare.err;
}

// W342 5-2-2's D, H, W, A, T, C under the names CX-Programmer shows.
TEST(CliFirstUse, CxProgrammerAreaNamesAreTheAreasOf5_2_2) {
    Finsd d({});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto w = fins(d, {"write", "DM100", "7"});
    EXPECT_EQ(w.exit_code, 0) << w.err;
    EXPECT_EQ(w.out, "wrote 1 word at D100\n");
    EXPECT_EQ(fins(d, {"read", "D100"}).out, "D100  7\n");
    for (const char* alias : {"HR0", "WR0", "AR448", "TIM5", "CNT5"}) {
        auto r = fins(d, {"read", alias});
        EXPECT_EQ(r.exit_code, 0) << alias << ": " << r.err;
    }
    auto lr = fins(d, {"read", "LR5"});
    EXPECT_EQ(lr.exit_code, 2);
    EXPECT_EQ(lr.err,
              "fins: bad address 'LR5': unknown memory area; the areas are CIO IR DR TK W H A T "
              "C D E (also TIM CNT DM HR WR AR)\n");
}

// W342 5-1-2 "Write-protected from network": the PLC checks the command's source node.
// Over UDP on loopback fins sends as 254, over TCP as the node the handshake allocates;
// the 2102 says which one was refused and probe shows it beforehand.
TEST(CliFirstUse, WriteProtection2102NamesTheSourceNodePer5_1_2) {
    Finsd d({"--network-write-protection", "all-except-listed", "--protect-node", "0.254"});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_EQ(fins(d, {"write", "D0", "1"}).exit_code, 0);
    auto tcp = fins(d, {"--tcp", "write", "D0", "1"});
    EXPECT_EQ(tcp.exit_code, 4) << tcp.err;
    EXPECT_TRUE(has(tcp.err, "(0x2102)")) << tcp.err;
    EXPECT_TRUE(has(tcp.err, "fins: fins sent as source node 0.")) << tcp.err;
    EXPECT_TRUE(has(tcp.err, "--source NET.NODE")) << tcp.err;
    auto chosen = fins(d, {"--tcp", "--source", "0.254", "write", "D0", "1"});
    EXPECT_EQ(chosen.exit_code, 0) << chosen.err;
    // What helps: the node, --source, and where the protection is set.
    auto udp = fins(d, {"--source", "0.20", "write", "D0", "1"});
    EXPECT_EQ(udp.exit_code, 4) << udp.err;
    EXPECT_EQ(udp.err.substr(udp.err.find('\n') + 1),
              "fins: fins sent as source node 0.20.0; network write protection lets only the "
              "nodes it lists write (--source NET.NODE sends as another node, `fins probe` "
              "shows the node in use). It is set in the PLC Setup (finsd: "
              "--network-write-protection and --protect-node, [protection] network_write and "
              "nodes, or `finsd ctl write-protect off`)\n")
        << udp.err;

    auto probe = fins(d, {"probe"});
    EXPECT_EQ(probe.exit_code, 0) << probe.err;
    EXPECT_TRUE(has(probe.out, "fins sends as node 0.254.0 (from the local address")) << probe.out;
    auto probe_tcp = fins(d, {"--json", "--tcp", "probe"});
    auto doc = nlohmann::json::parse(probe_tcp.out, nullptr, false);
    ASSERT_TRUE(doc.is_object()) << probe_tcp.out;
    EXPECT_TRUE(doc["local_node"].is_string());
}

TEST(CliFirstUse, DestNetNodeIsUnitZeroAndProbeAsksTheDest) {
    Finsd d({"--node", "10"});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto short_dest = fins(d, {"--dest", "0.10", "read", "D0"});
    EXPECT_EQ(short_dest.exit_code, 0) << short_dest.err;
    auto probe = fins(d, {"--dest", "0.10", "probe"});
    EXPECT_EQ(probe.exit_code, 0) << probe.err;
    EXPECT_TRUE(has(probe.out, "FINS node 0.10.0, CJ2H-CPU68-EIP")) << probe.out;
    EXPECT_FALSE(has(probe.out, "add --dest")) << probe.out;
    // A node that is not there is not found by asking node 00 instead.
    auto elsewhere = fins(d, {"--dest", "0.11.0", "probe"});
    EXPECT_EQ(elsewhere.exit_code, 4) << elsewhere.out;
    EXPECT_TRUE(has(elsewhere.err, "(0x0201)")) << elsewhere.err;
    EXPECT_EQ(fins(d, {"--dest", "0", "read", "D0"}).exit_code, 2);
    auto bad_source = fins(d, {"--source", "0.300", "probe"});
    EXPECT_EQ(bad_source.exit_code, 2) << bad_source.out;
    EXPECT_EQ(bad_source.err, "fins: --source '0.300' is not NET.NODE[.UNIT] (e.g. 0.20)\n");
    EXPECT_EQ(fins(d, {"--dest", "0.10.0.0", "read", "D0"}).exit_code, 2);
}

// W342 5-1-3 2101: "read-only ... or protected using a switch setting".
TEST(CliFirstUse, ReadOnly2101SaysWhetherTheDipSwitchProtectsPer5_1_3) {
    Finsd dip({"--dip-write-protection"});
    ASSERT_TRUE(dip.started()) << dip.result().err;
    ASSERT_EQ(fins(dip, {"stop"}).exit_code, 0);  // 03 08 runs in PROGRAM mode only
    auto clear = fins(dip, {"program-clear"});
    EXPECT_EQ(clear.exit_code, 4) << clear.err;
    EXPECT_TRUE(has(clear.err, "(0x2101)")) << clear.err;
    EXPECT_TRUE(has(clear.err,
                    "\nfins: the CPU Unit's DIP switch pin 1 is ON: user memory is "
                    "write-protected (W342 5-1-2); turn pin 1 OFF to write (finsd: started with "
                    "--dip-write-protection or [protection] dip_write = true)\n"))
        << clear.err;

    Finsd plain({});
    ASSERT_TRUE(plain.started()) << plain.result().err;
    auto a10 = fins(plain, {"write", "A10", "1"});
    EXPECT_EQ(a10.exit_code, 4) << a10.err;
    EXPECT_TRUE(has(a10.err, "DIP switch pin 1 is OFF: the area or file itself is read-only"))
        << a10.err;
}

TEST(CliFirstUse, OutputShowsWhatIsThereAlignedWithOneKeyPerFact) {
    // W342 5-3-15 on a CPU Unit without EM and with a unit that publishes no ID.
    Finsd cj1m({"--profile", "cj1m"});
    ASSERT_TRUE(cj1m.started()) << cj1m.result().err;
    auto data = fins(cj1m, {"cpu-data"});
    EXPECT_EQ(data.exit_code, 0) << data.err;
    EXPECT_FALSE(has(data.out, "largest EM bank")) << data.out;
    EXPECT_TRUE(has(data.out, "\nEM                 none\n")) << data.out;
    EXPECT_FALSE(has(data.out, "0x0000")) << data.out;
    EXPECT_TRUE(has(data.out, "\nCPU Bus Units      0\n")) << data.out;

    Finsd d({});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto em = fins(d, {"cpu-data", "--section", "area"});
    EXPECT_TRUE(has(em.out, "\nlargest EM bank    18 hex\n")) << em.out;
    auto multi = fins(d, {"read-multi", "D100", "CIO10.13", "T5"});
    EXPECT_EQ(multi.out, "D100      0\nCIO10.13  0\nT5        0\n");
    auto set = fins(d, {"--json", "clock", "--set", "2030-01-02 03:04:05"});
    auto set_doc = nlohmann::json::parse(set.out, nullptr, false);
    ASSERT_TRUE(set_doc.is_object()) << set.out;
    EXPECT_EQ(set_doc["time"], "2030-01-02 03:04:05");
    EXPECT_FALSE(set_doc.contains("set")) << set.out;

    Finsd lcb({"--profile", "cs1h-lcb", "--node", "12"});
    ASSERT_TRUE(lcb.started()) << lcb.result().err;
    auto raw = fins(lcb, {"--dest", "0.12.E1", "raw", "0240", "0001 0001 0006"});
    EXPECT_EQ(raw.exit_code, 0) << raw.err;
    EXPECT_TRUE(has(raw.out, "\nfrom 0.12.E1 sid")) << raw.out;
}

TEST(CliFirstUse, FinsHostAndFinsPortAreDefaultsFlagsOverride) {
    Finsd d({});
    ASSERT_TRUE(d.started()) << d.result().err;
    const std::string port = std::to_string(d.port());
    auto env = fins_env({"FINS_HOST=127.0.0.1", "FINS_PORT=" + port}, {"read", "D0"});
    EXPECT_EQ(env.exit_code, 0) << env.err;
    EXPECT_EQ(env.out, "D0  0\n");
    auto flag = fins_env({"FINS_PORT=1"}, {"--port", port, "read", "D0"});
    EXPECT_EQ(flag.exit_code, 0) << flag.err;
    auto bad = fins_env({"FINS_PORT=96OO"}, {"read", "D0"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_EQ(bad.err, "fins: FINS_PORT '96OO' is not a port number 1-65535\n");
    auto overridden = fins_env({"FINS_PORT=96OO"}, {"--port=" + port, "read", "D0"});
    EXPECT_EQ(overridden.exit_code, 0) << overridden.err;
    auto empty = fins_env({"FINS_HOST="}, {"read", "D0"});
    EXPECT_EQ(empty.exit_code, 2);
}

}  // namespace
}  // namespace fins::test
