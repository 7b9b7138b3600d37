// Conformance of PLC-initiated messages on FINS/TCP (W596 3; instruction_udp.hpp): a
// `finsd ctl sendcmd` to a node that is finsd's FINS/TCP client travels on that client's
// connection, server to client, and its answer client to server. Wireshark's dissector
// must read both frames (command code, ICF direction, end code) and flag nothing.
#include <poll.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"
#include "integration/support/process.hpp"
#include "integration/support/raw_socket.hpp"
#include "integration/tshark/tshark_support.hpp"

namespace fins::test {
namespace {

TEST(TsharkInstructions, SendCmdOnAFinsTcpClientsConnectionIsDissectedBothWays) {
    ScratchDir dir("tshark-instructions");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd finsd({"--no-udp", "--control", socket});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    tshark::Capture capture(finsd.port(), "instructions");
    if (!capture.ready())
        GTEST_SKIP() << "tshark missing, or no permission to capture on lo (root or wireshark)";

    asio::io_context io;
    RawTcp client(io, "127.0.0.1", finsd.port());
    const auto hello = client.handshake();
    ASSERT_EQ(hello.size(), 24u);
    const std::uint8_t node = hello[19];
    // The instruction waits for the answer as long as this test waits for anything (30 s),
    // not its 2 s default: the answer comes from this process, which a loaded machine may
    // not schedule for seconds.
    Child cmd({finsd_path, "ctl", "--socket", socket, "sendcmd", "--dest",
               "0." + std::to_string(node) + ".0", "--command", "0101 82000A00 0001", "--timeout",
               "30", "--json"});
    // The command comes once `finsd ctl` has started and asked finsd: a process start, which
    // on a loaded machine takes seconds (10 s seen at nice 19), longer than a receive's 5 s.
    // Wait for that event as long as ctl's own bound (Child::wait's 30 s).
    pollfd readable{client.native_handle(), POLLIN, 0};
    ::poll(&readable, 1, 30'000);
    const auto packet = client.receive_packet();
    ASSERT_GE(packet.size(), tcp_header_size + 12u) << "no command on the connection";
    const std::vector<std::uint8_t> command(packet.begin() + tcp_header_size, packet.end());
    EXPECT_EQ(command[0], 0x80);
    EXPECT_EQ(command[4], node);
    // The answer of a CPU Unit: addresses swapped, SID echoed, end code 0000, one word.
    const std::vector<std::uint8_t> answer{
        0xC0,       0x00,       0x02, command[6], command[7], command[8], command[3], command[4],
        command[5], command[9], 0x01, 0x01,       0x00,       0x00,       0xBE,       0xEF};
    client.send(tcp_packet(TcpCommand::frame, answer));
    const auto r = cmd.wait();
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out, nullptr, false)["result"]["response"], "01010000BEEF");

    // omron.icf.dtb is ICF bit 6, "response" (frames 1.2).
    const std::vector<std::string> fields{"omron.command", "omron.icf.dtb", "omron.response.code",
                                          "_ws.malformed", "_ws.expert.severity"};
    const auto decoded = capture.read_until(
        fields, [](const RunResult& d) { return tshark::count_rows(d, 0, "0x0101") == 2; });
    ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
    SCOPED_TRACE("tshark fields:\n" + decoded.out + decoded.err);
    int requests = 0;
    int responses = 0;
    for (const auto& line : tshark::split(decoded.out, '\n')) {
        if (line.empty()) continue;
        const auto f = tshark::split(line, '|');
        ASSERT_EQ(f.size(), fields.size()) << line;
        if (f[0] != "0x0101") continue;
        EXPECT_TRUE(f[3].empty()) << "malformed: " << line;
        for (const auto& s : tshark::split(f[4], ',')) {
            if (!s.empty()) {
                EXPECT_LT(std::stol(s), tshark::severity_warning) << line;
            }
        }
        if (f[1] == "0x01" || f[1] == "1" || f[1] == "True") {
            ++responses;
            EXPECT_EQ(f[2], "0x0000") << line;
        } else {
            ++requests;
        }
    }
    EXPECT_EQ(requests, 1);
    EXPECT_EQ(responses, 1);
}

}  // namespace
}  // namespace fins::test
