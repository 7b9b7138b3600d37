// PLC-initiated messages (W596 3) between real finsd processes on loopback: `finsd ctl
// send|recv|sendcmd` and [[schedule]] on node 1 against node 5 (another finsd) or a test
// UDP peer standing for "a host program that receives unsolicited FINS from a PLC".
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

// A UDP socket on 127.0.0.x standing for a host program: receives what finsd sends
// (every receive bounded by a 1 s timeout) and may answer.
class Peer {
  public:
    Peer(const std::string& ip, std::uint16_t port) : socket_(io_) {
        socket_.open(asio::ip::udp::v4());
        socket_.bind({asio::ip::make_address(ip), port});
        timeval tv{1, 0};
        ::setsockopt(socket_.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    }
    // The next datagram, or empty after `seconds` without one. Plain recvfrom: Asio's
    // blocking receive would wait past SO_RCVTIMEO.
    std::vector<std::uint8_t> receive(int seconds = 5) {
        for (int i = 0; i < seconds; ++i) {
            std::vector<std::uint8_t> buf(4096);
            sockaddr_in peer{};
            socklen_t size = sizeof peer;
            const auto n = ::recvfrom(socket_.native_handle(), buf.data(), buf.size(), 0,
                                      reinterpret_cast<sockaddr*>(&peer), &size);
            if (n >= 0) {
                buf.resize(static_cast<std::size_t>(n));
                from_ = asio::ip::udp::endpoint(asio::ip::address_v4(ntohl(peer.sin_addr.s_addr)),
                                                ntohs(peer.sin_port));
                return buf;
            }
        }
        return {};
    }
    // Answers `command` with `end_code` and `data`, as a CPU Unit does (frames 1.5), to
    // the sender of the last datagram or to `to`.
    void answer(const std::vector<std::uint8_t>& command, std::uint16_t end_code,
                const std::vector<std::uint8_t>& data = {},
                std::optional<asio::ip::udp::endpoint> to = std::nullopt) {
        std::vector<std::uint8_t> r{0xC0,
                                    0x00,
                                    command[2],
                                    command[6],
                                    command[7],
                                    command[8],
                                    command[3],
                                    command[4],
                                    command[5],
                                    command[9],
                                    command[10],
                                    command[11],
                                    static_cast<std::uint8_t>(end_code >> 8),
                                    static_cast<std::uint8_t>(end_code)};
        r.insert(r.end(), data.begin(), data.end());
        socket_.send_to(asio::buffer(r), to.value_or(from_));
    }
    [[nodiscard]] const asio::ip::udp::endpoint& from() const { return from_; }

  private:
    asio::io_context io_;
    asio::ip::udp::socket socket_;
    asio::ip::udp::endpoint from_;
};

class NetworkInstructions : public ::testing::Test {
  protected:
    // Node 5: a finsd on 127.0.0.1 with --node 5; node 1: a finsd on 127.0.0.1 whose
    // [[remote]] says where node 5 is, plus `extra` config.
    void start_pair(const std::string& extra = "") {
        node5_ = std::make_unique<Finsd>(std::vector<std::string>{"--node", "5"});
        ASSERT_TRUE(node5_->started()) << node5_->result().err;
        start_node1("[[remote]]\nnode = 5\naddress = \"127.0.0.1:" +
                    std::to_string(node5_->port()) + "\"\n" + extra);
    }
    void start_node1(const std::string& config) {
        const auto file = dir_.write("node1.toml", config);
        node1_ = std::make_unique<Finsd>(
            std::vector<std::string>{"--config", file, "--control", socket_path()});
        ASSERT_TRUE(node1_->started()) << node1_->result().err;
    }
    // A client of node 5 (DA1 = 5).
    std::unique_ptr<Client> client5() const {
        ClientOptions o;
        o.port = node5_->port();
        o.destination = {0, 5, 0};
        o.timeout = std::chrono::milliseconds(3000);
        auto c = Client::connect(o);
        EXPECT_TRUE(c.has_value());
        return c ? std::move(*c) : nullptr;
    }
    std::string socket_path() const { return (dir_.path() / "ctl.sock").string(); }
    RunResult ctl(std::vector<std::string> args) {
        std::vector<std::string> argv{finsd_path, "ctl", "--socket", socket_path()};
        argv.insert(argv.end(), args.begin(), args.end());
        return run(argv);
    }
    Json ctl_json(std::vector<std::string> args, int expected_exit) {
        args.push_back("--json");
        const auto r = ctl(args);
        EXPECT_EQ(r.exit_code, expected_exit) << r.out << r.err;
        return Json::parse(r.out, nullptr, false);
    }

    ScratchDir dir_{"instructions"};
    std::unique_ptr<Finsd> node5_;
    std::unique_ptr<Finsd> node1_;
};

TEST_F(NetworkInstructions, W596_3_SendWritesTheRemoteAndRcvReadsItBack) {
    start_pair("[memory]\nD100 = [0x1234, 0x5678, 0x9ABC]\n");
    auto send =
        ctl({"send", "--dest", "0.5.0", "--local", "D100", "--remote", "D200", "--count", "3"});
    EXPECT_EQ(send.exit_code, 0) << send.out << send.err;
    EXPECT_EQ(send.out.rfind("done:", 0), 0u) << send.out;
    auto c5 = client5();
    EXPECT_EQ(words_of(*c5, "D200", 3), (std::vector<std::uint16_t>{0x1234, 0x5678, 0x9ABC}));

    ASSERT_TRUE(c5->write_words(addr("D210"), std::vector<std::uint16_t>{7, 8}).has_value());
    auto recv = ctl_json(
        {"recv", "--dest", "0.5.0", "--remote", "D210", "--local", "D300", "--count", "2"}, 0);
    EXPECT_EQ(recv["result"]["words"], Json::array({7, 8}));
    EXPECT_EQ(recv["result"]["error_id"], "0000");
    auto c1 = node1_->client();
    EXPECT_EQ(words_of(*c1, "D300", 2), (std::vector<std::uint16_t>{7, 8}));
}

TEST_F(NetworkInstructions, W596_3_SendCmdReturnsTheAnswerAndRemoteEndCodesExit4) {
    start_pair();
    auto ok = ctl_json({"sendcmd", "--dest", "0.5.0", "--command", "0101 8200C800 0001"}, 0);
    EXPECT_EQ(ok["result"]["response"], "010100000000");
    // An address past the end of DM: the remote answers 1104, ErrorID 0800.
    auto refused = ctl_json({"sendcmd", "--dest", "0.5.0", "--command", "01018280000000FF"}, 4);
    EXPECT_EQ(refused["result"]["error_id"], "0800");
    EXPECT_EQ(refused["result"]["error_id_ex"], refused["result"]["end_code"]);
    EXPECT_NE(refused["result"]["end_code"], "0000");
}

// The largest command a frame holds (W596 3 CmdSize; 2,002 bytes: 01 02 with 997 words)
// passes through the control channel and the instruction.
TEST_F(NetworkInstructions, W596_3_SendCmdOfTheLargestCommandWorks) {
    start_pair();
    std::string command =
        "0102820000"
        "0003E5";
    for (int i = 0; i < 997; ++i)
        command += "ABCD";
    ASSERT_EQ(command.size(), 2 * 2002u);
    auto r = ctl_json({"sendcmd", "--dest", "0.5.0", "--command", command}, 0);
    EXPECT_EQ(r["result"]["response"], "01020000");
    auto c5 = client5();
    EXPECT_EQ(words_of(*c5, "D996", 1), (std::vector<std::uint16_t>{0xABCD}));
    auto too_long = ctl_json({"sendcmd", "--dest", "0.5.0", "--command", command + "00"}, 2);
    EXPECT_EQ(too_long["result"]["error_id"], "0400");
}

// "A host program that receives unsolicited FINS from a PLC": node 1 on 127.0.0.1 port P
// sends to node 7 by automatic generation, i.e. 127.0.0.7 port P, from its own port P.
TEST_F(NetworkInstructions, W596_3_HostProgramSeesEveryHeaderByteAndItsAnswerComesBack) {
    start_node1("");
    Peer host("127.0.0.7", node1_->port());
    Child cmd({finsd_path, "ctl", "--socket", socket_path(), "sendcmd", "--dest", "0.7.0",
               "--command", "0501", "--json"});
    const auto frame = host.receive();
    ASSERT_EQ(frame.size(), 12u);
    EXPECT_EQ(frame[0], 0x80);  // ICF: command, response required
    EXPECT_EQ(frame[1], 0x00);  // RSV
    EXPECT_EQ(frame[2], 0x02);  // GCT
    EXPECT_EQ(frame[3], 0x00);  // DNA
    EXPECT_EQ(frame[4], 0x07);  // DA1
    EXPECT_EQ(frame[5], 0x00);  // DA2
    EXPECT_EQ(frame[6], 0x00);  // SNA
    EXPECT_EQ(frame[7], 0x01);  // SA1: node 1
    EXPECT_EQ(frame[8], 0x00);  // SA2: CPU Unit
    EXPECT_EQ(frame[10], 0x05);
    EXPECT_EQ(frame[11], 0x01);
    EXPECT_EQ(host.from().address().to_string(), "127.0.0.1");
    EXPECT_EQ(host.from().port(), node1_->port());  // the node's own FINS port
    host.answer(frame, 0x0000, {0x43, 0x4A});
    const auto r = cmd.wait();
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    const auto j = Json::parse(r.out, nullptr, false);
    EXPECT_EQ(j["result"]["response"], "05010000434A");
}

// Issue 18 item 6: another process on the host of node 7 answers first, from another
// port; finsd takes only the answer from node 7's address and port.
TEST_F(NetworkInstructions, Issue18_AForgedAnswerFromAnotherPortIsIgnored) {
    start_node1("");
    Peer host("127.0.0.7", node1_->port());
    Peer forger("127.0.0.7", 0);
    Child cmd({finsd_path, "ctl", "--socket", socket_path(), "sendcmd", "--dest", "0.7.0",
               "--command", "0501", "--json"});
    const auto frame = host.receive();
    ASSERT_EQ(frame.size(), 12u);
    forger.answer(frame, 0x0000, {0x66, 0x66}, host.from());
    host.answer(frame, 0x0000, {0x43, 0x4A});
    const auto r = cmd.wait();
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    const auto j = Json::parse(r.out, nullptr, false);
    EXPECT_EQ(j["result"]["response"], "05010000434A");
}

TEST_F(NetworkInstructions, W596_3_NoAnswerRetriesThenExits5) {
    start_node1("");
    Peer silent("127.0.0.7", node1_->port());
    Child cmd({finsd_path, "ctl", "--socket", socket_path(), "send", "--dest", "0.7.0", "--local",
               "D0", "--remote", "D0", "--timeout", "0.2", "--retries", "3", "--json"});
    std::vector<std::vector<std::uint8_t>> seen;
    for (int i = 0; i < 4; ++i)
        if (auto f = silent.receive(); !f.empty()) seen.push_back(f);
    const auto r = cmd.wait();
    EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
    ASSERT_EQ(seen.size(), 4u);  // 1 + 3 retries
    for (const auto& f : seen)
        EXPECT_EQ(f, seen[0]);  // the same frame, the same SID
    EXPECT_TRUE(silent.receive(1).empty());
    const auto j = Json::parse(r.out, nullptr, false);
    EXPECT_EQ(j["result"]["error_id_ex"], "0205");
    EXPECT_EQ(j["result"]["transmissions"], 4);
    // CS/CJ: port 0's completion code and error flag (A203, A219 bit 0).
    auto c = node1_->client();
    EXPECT_EQ(words_of(*c, "A203", 1), (std::vector<std::uint16_t>{0x0205}));
    EXPECT_EQ(words_of(*c, "A219", 1), (std::vector<std::uint16_t>{0x0001}));
    EXPECT_EQ(words_of(*c, "A202", 1), (std::vector<std::uint16_t>{0x00FF}));
}

TEST_F(NetworkInstructions, W596_3_NoResponseModeSetsIcfBit0) {
    start_node1("");
    Peer host("127.0.0.7", node1_->port());
    auto r = ctl({"send", "--dest", "0.7.0", "--local", "D0", "--remote", "D0", "--no-response"});
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    const auto frame = host.receive();
    ASSERT_GE(frame.size(), 12u);
    EXPECT_EQ(frame[0], 0x81);
}

TEST_F(NetworkInstructions, W596_3_ParameterErrorsExit2WithErrorId0400) {
    start_pair();
    auto many = ctl_json(
        {"send", "--dest", "0.5.0", "--local", "D0", "--remote", "D0", "--count", "991"}, 2);
    EXPECT_EQ(many["result"]["error_id"], "0400");
    auto rcv = ctl_json(
        {"recv", "--dest", "0.5.0", "--local", "D0", "--remote", "D0", "--no-response"}, 2);
    EXPECT_EQ(rcv["result"]["error_id"], "0400");
    auto usage = ctl({"send", "--dest", "0.5.0", "--local", "D0"});
    EXPECT_EQ(usage.exit_code, 2);
    auto bad_dest = ctl({"recv", "--dest", "0.5.0.9", "--local", "D0", "--remote", "D0"});
    EXPECT_EQ(bad_dest.exit_code, 2);
    EXPECT_NE(bad_dest.err.find("dest"), std::string::npos) << bad_dest.err;
}

// 32 scheduled instructions to a silent host stay in flight (10 s timeout): the 33rd,
// from the control channel, ends at once with 0800 / 0104 (W596 3: at most 32).
TEST_F(NetworkInstructions, W596_3_TheThirtyThirdInstructionEndsWith0104) {
    std::string config;
    for (int i = 0; i < 32; ++i)
        config +=
            "[[schedule]]\nevery = \"10ms\"\ninstruction = \"send\"\ndest = \"0.7.0\"\n"
            "local = \"D0\"\nremote = \"D0\"\ntimeout = 100\n";
    start_node1(config);
    // Bounded wait until the schedule filled every port.
    Json status;
    for (int i = 0; i < 100; ++i) {
        status = Json::parse(ctl({"instructions"}).out, nullptr, false);
        if (status["instructions"]["in_flight"] == 32) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_EQ(status["instructions"]["in_flight"], 32) << status.dump();
    EXPECT_EQ(status["instructions"]["available"], false);
    auto busy = ctl_json({"send", "--dest", "0.7.0", "--local", "D0", "--remote", "D0"}, 6);
    EXPECT_EQ(busy["result"]["error_id"], "0800");
    EXPECT_EQ(busy["result"]["error_id_ex"], "0104");
}

TEST_F(NetworkInstructions, ScheduleSendsAtItsPeriod) {
    start_pair(
        "[memory]\nD100 = [0x0A0B]\n"
        "[[schedule]]\nevery = \"50ms\"\ninstruction = \"send\"\ndest = \"0.5.0\"\n"
        "local = \"D100\"\nremote = \"D400\"\ncount = 1\nretries = 1\n");
    auto c5 = client5();
    std::vector<std::uint16_t> got;
    for (int i = 0; i < 100 && got != std::vector<std::uint16_t>{0x0A0B}; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        got = words_of(*c5, "D400", 1);
    }
    EXPECT_EQ(got, (std::vector<std::uint16_t>{0x0A0B}));
    const auto status = Json::parse(ctl({"instructions"}).out, nullptr, false);
    ASSERT_EQ(status["schedule"].size(), 1u) << status.dump();
    EXPECT_GE(status["schedule"][0]["done"].get<int>(), 1);
    EXPECT_EQ(status["schedule"][0]["last_error_id"], "0000");
}

TEST_F(NetworkInstructions, ConfigErrorsNameTheEntry) {
    const auto file =
        dir_.write("bad.toml",
                   "[[schedule]]\nevery = \"1s\"\ninstruction = \"send\"\ndest = \"0.5.0\"\n"
                   "local = \"D100\"\nremote = \"D200\"\nretries = 16\n");
    auto r = run({finsd_path, "--config", file, "--port", "0"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("schedule[0].retries"), std::string::npos) << r.err;
    const auto local =
        dir_.write("local.toml",
                   "[[schedule]]\nevery = \"1s\"\ninstruction = \"recv\"\ndest = \"0.5.0\"\n"
                   "local = \"A100\"\nremote = \"D200\"\n");
    r = run({finsd_path, "--config", local, "--port", "0"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("schedule[0]"), std::string::npos) << r.err;
    const auto remote = dir_.write("remote.toml", "[[remote]]\nnode = 5\naddress = \"nowhere\"\n");
    r = run({finsd_path, "--config", remote, "--port", "0"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("remote[0].address"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace fins::test
