// FINS over Host Link end to end (issue 9; W342 3-5, 5-3-1): fins::Client and the `fins`
// CLI over a socat pty pair against `finsd --serial cpu=...`; a raw host on the line
// for bad FCS, other unit numbers, garbage and over-long lines; a fake slave for the
// client's typed errors; a port that vanishes while finsd keeps serving Ethernet.
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "fins/commands/clock.hpp"
#include "fins/commands/diagnostics.hpp"
#include "fins/host_link.hpp"
#include "integration/support/finsd_process.hpp"
#include "integration/support/pty_pair.hpp"

namespace fins::test {
namespace {

const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";

// One end of the pty pair opened raw, for writing frames by hand.
class RawLine {
  public:
    explicit RawLine(const std::string& path) : fd_(::open(path.c_str(), O_RDWR | O_NOCTTY)) {
        termios t{};
        if (fd_ >= 0 && ::tcgetattr(fd_, &t) == 0) {
            ::cfmakeraw(&t);
            ::tcsetattr(fd_, TCSANOW, &t);
        }
    }
    ~RawLine() {
        if (fd_ >= 0) ::close(fd_);
    }
    RawLine(const RawLine&) = delete;
    RawLine& operator=(const RawLine&) = delete;
    [[nodiscard]] bool ok() const { return fd_ >= 0; }

    void write(const std::string& text) const {
        std::size_t done = 0;
        while (done < text.size()) {
            const auto n = ::write(fd_, text.data() + done, text.size() - done);
            if (n <= 0) return;
            done += static_cast<std::size_t>(n);
        }
    }
    // Characters up to and including the first CR, or "" after `timeout`.
    std::string read_frame(std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < deadline) {
            const auto cr = pending_.find('\r');
            if (cr != std::string::npos) {
                auto frame = pending_.substr(0, cr + 1);
                pending_.erase(0, cr + 1);
                return frame;
            }
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, 50) <= 0) continue;
            char buf[512];
            const auto n = ::read(fd_, buf, sizeof buf);
            if (n <= 0) break;
            pending_.append(buf, static_cast<std::size_t>(n));
        }
        return {};
    }

  private:
    int fd_ = -1;
    std::string pending_;
};

std::string with_fcs(const std::string& body) {
    std::uint8_t fcs = 0;
    for (char c : body)
        fcs ^= static_cast<std::uint8_t>(c);
    return body + fmt::format("{:02X}*\r", fcs);
}

// "@UUFA0" + ICF DA2 SA2 SID + 01 01 (read 1 word of D100), direct form.
std::string read_d100(unsigned unit) {
    return with_fcs(fmt::format("@{:02}FA0000000000101820064000001", unit));
}

ClientOptions serial_options(const std::string& device, std::uint8_t unit = 0) {
    ClientOptions o;
    o.protocol = ClientOptions::Protocol::serial;
    o.serial.device = device;
    o.host_link_unit = unit;
    o.timeout = std::chrono::milliseconds(3000);
    return o;
}

class HostLink : public ::testing::Test {
  protected:
    void SetUp() override {
        ASSERT_TRUE(pty_.ok()) << "socat did not start";
        finsd_ = std::make_unique<Finsd>(std::vector<std::string>{"--serial", "cpu=" + pty_.a()});
        ASSERT_TRUE(finsd_->started()) << finsd_->result().err;
    }
    PtyPair pty_;
    std::unique_ptr<Finsd> finsd_;
};

TEST_F(HostLink, W342_3_5_ClientReadsAndWritesThroughFinsdSerialPort) {
    auto c = Client::connect(serial_options(pty_.b()));
    ASSERT_TRUE(c) << c.error().message();
    auto& client = **c;
    const std::vector<std::uint16_t> words{1, 2, 0xBEEF};
    ASSERT_TRUE(client.write_words(addr("D100"), words));
    EXPECT_EQ(words_of(client, "D100", 3), words);
    ASSERT_TRUE(client.write_float(addr("D200"), 1.5f));
    EXPECT_EQ(client.read_float(addr("D200")).value_or(0), 1.5f);
    // Over 269 words: split into Host Link-sized requests (W342 5-2-2, SYSWAY 269/267).
    std::vector<std::uint16_t> many(700);
    for (std::size_t i = 0; i < many.size(); ++i)
        many[i] = static_cast<std::uint16_t>(i * 7);
    ASSERT_TRUE(client.write_words(addr("D1000"), many));
    EXPECT_EQ(words_of(client, "D1000", many.size()), many);
    EXPECT_EQ(client.stats().retransmitted, 0u);
    // Other command groups: status, clock; the Ethernet side sees the same PLC.
    EXPECT_TRUE(client.send(CpuUnitStatusRead{}));
    EXPECT_TRUE(client.send(ClockRead{}));
    auto udp = finsd_->client();
    ASSERT_NE(udp, nullptr);
    EXPECT_EQ(words_of(*udp, "D100", 3), words);
    // The network form (a --dest with node) reaches the same CPU Unit.
    auto o = serial_options(pty_.b());
    o.destination = NodeAddress{0, 1, 0};
    c->reset();
    auto network = Client::connect(o);
    ASSERT_TRUE(network);
    EXPECT_EQ(words_of(**network, "D100", 1), std::vector<std::uint16_t>{1});
}

TEST_F(HostLink, CliRunsVerbsOverSerial) {
    const auto dev = pty_.b();
    auto w = run({fins_bin, "--serial", dev, "write", "D10", "11", "22"});
    EXPECT_EQ(w.exit_code, 0) << w.err;
    auto r = run({fins_bin, "--serial", dev + ",baud=9600,parity=even,data=7,stop=2", "--json",
                  "read", "D10", "2"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("11"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("22"), std::string::npos) << r.out;
    auto fill = run({fins_bin, "--serial", dev, "fill", "D20", "5", "7"});
    EXPECT_EQ(fill.exit_code, 0) << fill.err;
    auto probe = run({fins_bin, "--serial", dev, "probe"});
    EXPECT_EQ(probe.exit_code, 0) << probe.err;
    EXPECT_NE(probe.out.find("over Host Link"), std::string::npos) << probe.out;
    auto status = run({fins_bin, "--serial", dev, "status"});
    EXPECT_EQ(status.exit_code, 0) << status.err;
    // File memory in chunks that fit Host Link frames (22 03 / 22 02).
    ScratchDir dir("hostlink");
    std::string content;
    for (int i = 0; i < 3000; ++i)
        content += static_cast<char>('A' + i % 26);
    const auto source = dir.write("src.bin", content);
    const auto target = (dir.path() / "dst.bin").string();
    auto put = run({fins_bin, "--serial", dev, "files", "put", source, "HL.BIN"});
    EXPECT_EQ(put.exit_code, 0) << put.err;
    auto get = run({fins_bin, "--serial", dev, "files", "get", "HL.BIN", target});
    EXPECT_EQ(get.exit_code, 0) << get.err;
    std::ifstream in(target, std::ios::binary);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), content);
    // End code from the PLC: exit 4 as over Ethernet.
    auto bad = run({fins_bin, "--serial", dev, "raw", "0101", "82FFFF000001"});
    EXPECT_EQ(bad.exit_code, 4) << bad.out << bad.err;
    // Usage errors name the option.
    auto usage = run({fins_bin, "--serial", dev + ",baud=12345", "read", "D0"});
    EXPECT_EQ(usage.exit_code, 2);
    EXPECT_NE(usage.err.find("--serial: baud '12345'"), std::string::npos) << usage.err;
    auto missing =
        run({fins_bin, "--serial", "/dev/finskit-none", "--timeout", "0.2", "read", "D0"});
    EXPECT_EQ(missing.exit_code, 3) << missing.err;
}

TEST_F(HostLink, W342p125_BadFcsGetsHostLinkEndCode13) {
    RawLine line(pty_.b());
    ASSERT_TRUE(line.ok());
    auto frame = read_d100(0);
    frame[frame.size() - 3] = frame[frame.size() - 3] == '0' ? '1' : '0';
    line.write(frame);
    EXPECT_EQ(line.read_frame(), with_fcs("@00FA13"));
    // A C-mode command (header RD): 16 command not supported; odd text: 14 format error.
    line.write(with_fcs("@00RD00000001"));
    EXPECT_EQ(line.read_frame(), with_fcs("@00FA16"));
    line.write(with_fcs("@00FA00000000001018"));
    EXPECT_EQ(line.read_frame(), with_fcs("@00FA14"));
    // A terminated frame over 1,114 characters: 18 frame length error.
    line.write(with_fcs("@00FA08000020000000000000001028200000000" + std::string(1100, '0')));
    EXPECT_EQ(line.read_frame(), with_fcs("@00FA18"));
    // And a good frame is still answered after all that.
    line.write(read_d100(0));
    EXPECT_EQ(line.read_frame().substr(0, 23), "@00FA004000000001010000");
}

TEST_F(HostLink, MultiDropFramesForAnotherUnitAreIgnored) {
    RawLine line(pty_.b());
    ASSERT_TRUE(line.ok());
    line.write(read_d100(7));
    line.write(read_d100(0));
    // Only unit 0's answer comes back.
    EXPECT_EQ(line.read_frame().substr(0, 7), "@00FA00");
    EXPECT_EQ(line.read_frame(std::chrono::milliseconds(300)), "");
    // A client for unit 7 times out (no answer, no error answer).
    auto o = serial_options(pty_.b(), 7);
    o.timeout = std::chrono::milliseconds(300);
    auto c = Client::connect(o);
    ASSERT_TRUE(c);
    auto r = (*c)->read_words(addr("D0"), 1);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(ClientError::timeout));
}

TEST_F(HostLink, GarbageAndOverlongLinesAreSkipped) {
    RawLine line(pty_.b());
    ASSERT_TRUE(line.ok());
    line.write("noise\r\n\x01\x02 ");
    line.write("@00FA" + std::string(5000, '0'));  // no CR: dropped unanswered
    line.write("\r" + read_d100(0));
    EXPECT_EQ(line.read_frame().substr(0, 7), "@00FA00");
}

TEST(HostLinkClient, TypedErrorsFromTheLine) {
    PtyPair pty;
    ASSERT_TRUE(pty.ok());
    RawLine slave(pty.a());
    ASSERT_TRUE(slave.ok());
    auto o = serial_options(pty.b());
    o.timeout = std::chrono::milliseconds(2000);
    auto c = Client::connect(o);
    ASSERT_TRUE(c);
    const std::vector<std::string> answers{
        with_fcs("@00FA13"),                 // the PLC saw a bad FCS
        "@00FA004000000001010000000099*\r",  // our answer with a bad FCS
    };
    std::thread fake([&] {
        for (const auto& a : answers) {
            if (slave.read_frame().empty()) return;
            slave.write(a);
        }
    });
    auto first = (*c)->read_words(addr("D0"), 1);
    auto second = (*c)->read_words(addr("D0"), 1);
    fake.join();
    ASSERT_FALSE(first);
    EXPECT_EQ(first.error(), make_error_code(HostLinkEndCode::fcs_error));
    EXPECT_EQ((*c)->describe(first.error()),
              pty.b() + " unit 0: FCS error (Host Link end code 13)");
    ASSERT_FALSE(second);
    EXPECT_EQ(second.error(), make_error_code(HostLinkError::bad_fcs));
}

// A PLC reached only through its serial port: UDP and TCP off is a real set-up then
// (without a Host Link port it is refused: finsd_config_test).
TEST(HostLinkFinsd, SerialOnlyPlcServesWithUdpAndTcpOff) {
    PtyPair pty;
    ASSERT_TRUE(pty.ok()) << "socat did not start";
    Finsd finsd({"--no-udp", "--no-tcp", "--serial", "cpu=" + pty.a()});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    EXPECT_EQ(finsd.port(), 0);  // "listening 0": no network port
    auto c = Client::connect(serial_options(pty.b()));
    ASSERT_TRUE(c) << c.error().message();
    const std::vector<std::uint16_t> words{7, 8, 9};
    ASSERT_TRUE((*c)->write_words(addr("D100"), words));
    EXPECT_EQ(words_of(**c, "D100", 3), words);
    c->reset();
    EXPECT_EQ(finsd.stop().exit_code, 0);
}

TEST(HostLinkFinsd, VanishingPortIsLoggedOnceAndEthernetKeepsServing) {
    auto pty = std::make_unique<PtyPair>();
    ASSERT_TRUE(pty->ok());
    Finsd finsd({"--serial", "cpu=" + pty->a()});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    {
        auto c = Client::connect(serial_options(pty->b()));
        ASSERT_TRUE(c);
        EXPECT_TRUE((*c)->read_words(addr("D0"), 1));
    }
    pty->close();  // socat gone: both devices vanish
    EXPECT_TRUE(finsd.child().wait_for_stderr("serial cpu (" + pty->a() + "): lost"));
    for (int i = 0; i < 3; ++i) {  // and through a few reopen attempts
        auto c = finsd.client(ClientOptions{});
        ASSERT_TRUE(c);
        EXPECT_TRUE(c->read_words(addr("D0"), 1));
        std::this_thread::sleep_for(std::chrono::milliseconds(400));
    }
    auto result = finsd.stop();
    EXPECT_EQ(result.exit_code, 0);
    // Logged once: no line per failed reopen.
    EXPECT_EQ(result.err.find("serial cpu"), std::string::npos) << result.err;
}

}  // namespace
}  // namespace fins::test
