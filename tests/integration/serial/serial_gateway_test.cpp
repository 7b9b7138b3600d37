// The Serial Gateway end to end (W342 5-3-46 .. 5-3-48; frames-serial-files.md 2): a
// FINS/UDP client -> finsd's server -> a gateway port on one end of a socat pty pair ->
// a real slave on the other end: the project's simulated CompoWay/F controller
// (tools/compowayf_sim) and libmodbus's Modbus-RTU slave (tests/tools). Faults: no
// answer (0205), a bad checksum (0206), a flood (0204), a port that disappears (0205
// while other ports and the CPU Unit keep answering).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "codec/test_support.hpp"
#include "fins/frame.hpp"
#include "integration/support/process.hpp"
#include "integration/support/pty_pair.hpp"
#include "integration/support/raw_socket.hpp"
#include "plc/plc.hpp"
#include "server/serial/serial_ports.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using namespace std::chrono_literals;

const std::string bin_dir = FINS_BIN_DIR;

std::vector<std::uint8_t> ascii(std::string_view s) {
    return {s.begin(), s.end()};
}

std::string text_of(const std::vector<std::uint8_t>& frame) {
    return frame.size() > 14 ? std::string(frame.begin() + 14, frame.end()) : std::string{};
}

server::GatewayPortConfig port_config(const std::string& name, std::uint8_t unit,
                                      const std::string& device,
                                      std::chrono::milliseconds timeout = 2s) {
    server::GatewayPortConfig c;
    c.name = name;
    c.unit_address = unit;
    c.line.device = device;
    c.line.data_bits = 8;
    c.timeout = timeout;
    return c;
}

// finsd's server with gateway ports, on its own I/O thread.
class Gateway {
  public:
    explicit Gateway(const std::vector<server::GatewayPortConfig>& configs) {
        server::ServerOptions options;
        options.port = 0;
        server_ = server::Server::start(io_, plc_, options).value();
        for (const auto& c : configs) {
            auto port = std::make_shared<server::SerialGatewayPort>(io_, c);
            EXPECT_FALSE(port->open()) << c.line.device;
            ports_.add(port);
        }
        server_->attach_serial_ports(&ports_);
        thread_ = std::thread([this] { io_.run(); });
        fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
        set_receive_timeout(fd_, 10);
    }
    ~Gateway() {
        asio::post(io_, [this] {
            ports_.close_all();
            server_->stop();
            io_.stop();
        });
        thread_.join();
        ::close(fd_);
    }

    void send(std::uint8_t unit, CommandCode code, const std::vector<std::uint8_t>& params,
              std::uint8_t sid = 0x11) {
        auto frame = request_frame(code, params, sid);
        frame[5] = unit;  // DA2: the serial port's unit address
        send_raw(frame);
    }
    std::vector<std::uint8_t> receive() {
        std::vector<std::uint8_t> buf(max_frame_size);
        const auto n = ::recv(fd_, buf.data(), buf.size(), 0);
        buf.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
        return buf;
    }
    void send_raw(const std::vector<std::uint8_t>& frame) {
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_port = htons(server_->udp_port());
        to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        ::sendto(fd_, frame.data(), frame.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    }
    std::vector<std::uint8_t> call_raw(const std::vector<std::uint8_t>& frame) {
        send_raw(frame);
        return receive();
    }
    std::vector<std::uint8_t> call(std::uint8_t unit, CommandCode code,
                                   const std::vector<std::uint8_t>& params) {
        send(unit, code, params);
        return receive();
    }

  private:
    asio::io_context io_{1};
    plc::Plc plc_;
    std::unique_ptr<server::Server> server_;
    server::SerialPorts ports_;
    std::thread thread_;
    int fd_ = -1;
};

constexpr CommandCode compoway{0x28, 0x03};
constexpr CommandCode modbus_rtu{0x28, 0x04};
constexpr std::uint8_t scu1_port1 = server::scu_port_unit_address(1, 1);  // 84
constexpr std::uint8_t scu1_port2 = server::scu_port_unit_address(1, 2);  // 85

TEST(SerialGateway, W342_5_3_46_PortUnitAddressTables) {
    EXPECT_EQ(server::scu_port_unit_address(0, 1), 0x80);
    EXPECT_EQ(server::scu_port_unit_address(0, 2), 0x81);
    EXPECT_EQ(server::scu_port_unit_address(15, 1), 0xBC);
    EXPECT_EQ(server::scu_port_unit_address(15, 2), 0xBD);
    EXPECT_EQ(server::board_port_unit_address(1), 0xE4);
    EXPECT_EQ(server::board_port_unit_address(2), 0xE5);
}

TEST(SerialGateway, W342_5_3_46_CompowayFReadWriteAndOperationCommand) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Child sim({bin_dir + "/fins_compowayf_sim", line.b(), "--node", "1"});
    ASSERT_EQ(sim.read_line(), "ready");
    Gateway gw({port_config("scu1.1", scu1_port1, line.a())});

    // Read the process value (C0 0000): 25 = 00000019.
    auto r = gw.call(scu1_port1, compoway,
                     ascii("01000"
                           "0101"
                           "C00000000001"));
    EXPECT_EQ(end_code_of(r), 0x0000);
    EXPECT_EQ(text_of(r),
              "0100"
              "00"
              "0101"
              "0000"
              "00000019");

    // A write before communications writing is ON: the slave's 2203 inside a 0000 answer.
    const auto write_sp = ascii(
        "01000"
        "0102"
        "C10000000001"
        "000000C8");
    r = gw.call(scu1_port1, compoway, write_sp);
    EXPECT_EQ(end_code_of(r), 0x0000);
    EXPECT_EQ(text_of(r),
              "0100"
              "0F"
              "0102"
              "2203");

    r = gw.call(scu1_port1, compoway,
                ascii("01000"
                      "3005"
                      "0001"));  // comms writing ON
    EXPECT_EQ(text_of(r),
              "0100"
              "00"
              "3005"
              "0000");
    r = gw.call(scu1_port1, compoway, write_sp);
    EXPECT_EQ(text_of(r),
              "0100"
              "00"
              "0102"
              "0000");
    r = gw.call(scu1_port1, compoway,
                ascii("01000"
                      "0101"
                      "C10000000001"));
    EXPECT_EQ(text_of(r),
              "0100"
              "00"
              "0101"
              "0000"
              "000000C8");

    // Broadcast: nothing comes back from the line, the port answers 0000 with no data.
    r = gw.call(scu1_port1, compoway,
                ascii("XX000"
                      "0601"));
    EXPECT_EQ(end_code_of(r), 0x0000);
    EXPECT_EQ(r.size(), 14U);
}

TEST(SerialGateway, W342_5_3_47_ModbusRtuAgainstLibmodbus) {
    if (!std::filesystem::exists(bin_dir + "/fins_test_modbus_slave"))
        GTEST_SKIP() << "libmodbus-dev was not found at configure time";
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Child slave({bin_dir + "/fins_test_modbus_slave", line.b(), "1"});
    ASSERT_EQ(slave.read_line(), "ready");
    Gateway gw({port_config("scu1.2", scu1_port2, line.a())});

    // Read holding registers 4 and 5 (they hold 4 and 5).
    auto r = gw.call(scu1_port2, modbus_rtu, hex("01 03 00 04 00 02"));
    EXPECT_EQ(end_code_of(r), 0x0000);
    EXPECT_EQ(std::vector<std::uint8_t>(r.begin() + 14, r.end()), hex("01 03 04 00 04 00 05"));
    // Write register 7, read it back.
    r = gw.call(scu1_port2, modbus_rtu, hex("01 06 00 07 12 34"));
    EXPECT_EQ(std::vector<std::uint8_t>(r.begin() + 14, r.end()), hex("01 06 00 07 12 34"));
    r = gw.call(scu1_port2, modbus_rtu, hex("01 03 00 07 00 01"));
    EXPECT_EQ(std::vector<std::uint8_t>(r.begin() + 14, r.end()), hex("01 03 02 12 34"));
    // An exception response from the slave comes back inside a normal FINS answer.
    r = gw.call(scu1_port2, modbus_rtu, hex("01 03 01 00 00 01"));
    EXPECT_EQ(end_code_of(r), 0x0000);
    EXPECT_EQ(std::vector<std::uint8_t>(r.begin() + 14, r.end()), hex("01 83 02"));
}

TEST(SerialGateway, W342_5_3_48_ModbusAsciiAgainstPymodbus) {
    if (!std::filesystem::exists("/usr/bin/python3"))
        GTEST_SKIP() << "Debian's python3 (with python3-pymodbus) is not installed";
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Child slave({"/usr/bin/python3",
                 std::string(FINS_SOURCE_DIR) + "/tests/tools/modbus_ascii_slave.py", line.b(),
                 "2"});
    const auto ready = slave.read_line(std::chrono::seconds(20));
    if (ready != "ready")
        GTEST_SKIP() << "pymodbus slave did not start (python3-pymodbus missing?)";
    Gateway gw({port_config("scu1.2", scu1_port2, line.a())});

    // Read holding registers 4 and 5 of slave 2 (they hold 4 and 5); the answer's LRC is
    // checked and stripped by the port.
    auto r = gw.call(scu1_port2, CommandCode{0x28, 0x05}, ascii("020300040002"));
    EXPECT_EQ(end_code_of(r), 0x0000);
    EXPECT_EQ(text_of(r), "02030400040005");
    r = gw.call(scu1_port2, CommandCode{0x28, 0x05}, ascii("020600071234"));
    EXPECT_EQ(text_of(r), "020600071234");
    r = gw.call(scu1_port2, CommandCode{0x28, 0x05}, ascii("020300070001"));
    EXPECT_EQ(text_of(r), "0203021234");
    // An exception from the slave (illegal data address) inside a normal answer.
    r = gw.call(scu1_port2, CommandCode{0x28, 0x05}, ascii("020301000001"));
    EXPECT_EQ(end_code_of(r), 0x0000);
    EXPECT_EQ(text_of(r), "028302");
}

TEST(SerialGateway, W336_6_6_2_NoAnswerWithinTheTimeoutIs0205) {
    PtyPair line;  // nobody on the other end
    ASSERT_TRUE(line.ok());
    Gateway gw({port_config("scu1.1", scu1_port1, line.a(), 200ms)});
    auto r = gw.call(scu1_port1, compoway,
                     ascii("01000"
                           "0101"
                           "C00000000001"));
    EXPECT_EQ(end_code_of(r), 0x0205);
    r = gw.call(scu1_port1, modbus_rtu, hex("01 03 00 00 00 01"));
    EXPECT_EQ(end_code_of(r), 0x0205);
}

TEST(SerialGateway, W336_11_3_2_BadChecksumIs0206) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Child sim({bin_dir + "/fins_compowayf_sim", line.b(), "--garble"});
    ASSERT_EQ(sim.read_line(), "ready");
    Gateway gw({port_config("scu1.1", scu1_port1, line.a())});
    const auto r = gw.call(scu1_port1, compoway,
                           ascii("01000"
                                 "0101"
                                 "C00000000001"));
    EXPECT_EQ(end_code_of(r), 0x0206);
}

TEST(SerialGateway, W336_6_1_4_FloodIsBoundedWith0204InOrder) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Gateway gw({port_config("scu1.1", scu1_port1, line.a(), 100ms)});
    constexpr int sent = 9;
    for (int i = 0; i < sent; ++i)
        gw.send(scu1_port1, compoway,
                ascii("01000"
                      "0101"
                      "C00000000001"),
                static_cast<std::uint8_t>(i));
    int busy = 0;
    int timeouts = 0;
    int last_timeout_sid = -1;
    for (int i = 0; i < sent; ++i) {
        const auto r = gw.receive();
        ASSERT_GE(r.size(), 14U);
        if (end_code_of(r) == 0x0204) ++busy;
        if (end_code_of(r) == 0x0205) {
            ++timeouts;
            EXPECT_GT(r[9], last_timeout_sid);  // served in arrival order
            last_timeout_sid = r[9];
        }
    }
    // One on the line and five waiting (W336 6-1-4); the rest are refused at once.
    EXPECT_EQ(timeouts, 1 + static_cast<int>(server::SerialGatewayPort::max_queued));
    EXPECT_EQ(busy, sent - timeouts);
}

TEST(SerialGateway, PortThatDisappearsAnswers0205AndTheRestKeepServing) {
    PtyPair gone;
    PtyPair other;
    ASSERT_TRUE(gone.ok());
    ASSERT_TRUE(other.ok());
    Child sim({bin_dir + "/fins_compowayf_sim", other.b()});
    ASSERT_EQ(sim.read_line(), "ready");
    Gateway gw({port_config("scu1.1", scu1_port1, gone.a(), 300ms),
                port_config("scu1.2", scu1_port2, other.a())});
    gone.close();
    auto r = gw.call(scu1_port1, compoway,
                     ascii("01000"
                           "0101"
                           "C00000000001"));
    EXPECT_EQ(end_code_of(r), 0x0205);
    r = gw.call(scu1_port1, compoway,
                ascii("01000"
                      "0101"
                      "C00000000001"));
    EXPECT_EQ(end_code_of(r), 0x0205);
    r = gw.call(scu1_port2, compoway,
                ascii("01000"
                      "0101"
                      "C00000000001"));
    EXPECT_EQ(end_code_of(r), 0x0000);
    r = gw.call(cpu_unit, CommandCode{0x01, 0x01}, hex("82 00 00 00 00 01"));
    EXPECT_EQ(end_code_of(r), 0x0000);
}

// Host Link FINS conversion faults (W342 5-1-1; choices in host_link_relay.cpp): no
// slave answers (0205), an answer that is not a valid Host Link frame (0206).
TEST(SerialGateway, W342_5_1_1_HostLinkRelayTimeoutAndGarbledAnswer) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Gateway gw({port_config("scu1.1", scu1_port1, line.a(), 300ms)});
    auto frame = request_frame(CommandCode{0x01, 0x01}, hex("82 00 64 00 00 01"));
    frame[3] = scu1_port1;  // DNA: the port's unit address (no routing table)
    frame[4] = 3 + 1;       // DA1: Host Link unit 3
    auto r = gw.call_raw(frame);
    EXPECT_EQ(end_code_of(r), 0x0205);

    // A slave that answers with a bad FCS.
    const int slave = ::open(line.b().c_str(), O_RDWR | O_NOCTTY);
    ASSERT_GE(slave, 0);
    gw.send_raw(frame);
    std::array<char, 256> got{};
    ASSERT_GT(::read(slave, got.data(), got.size()), 0);  // the Host Link command
    const std::string_view bad = "@03FA0040000000000101000000FF*\r";
    ASSERT_EQ(::write(slave, bad.data(), bad.size()), static_cast<ssize_t>(bad.size()));
    r = gw.receive();
    EXPECT_EQ(end_code_of(r), 0x0206);
    // The answer comes from the address the client asked.
    ASSERT_GE(r.size(), 10U);
    EXPECT_EQ(r[6], scu1_port1);
    EXPECT_EQ(r[7], 3 + 1);
    ::close(slave);
}

TEST(SerialGateway, W342_5_1_1_OnlyGatewayCommandsGoToAPortAndNotToTheCpu) {
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Gateway gw({port_config("scu1.1", scu1_port1, line.a(), 200ms)});
    // A memory read addressed to the port's own unit address: undefined there.
    auto r = gw.call(scu1_port1, CommandCode{0x01, 0x01}, hex("82 00 00 00 00 01"));
    EXPECT_EQ(end_code_of(r), 0x0401);
    // 28 03 to the CPU Unit: no serial port of its own is modelled.
    r = gw.call(cpu_unit, compoway,
                ascii("01000"
                      "0101"
                      "C00000000001"));
    EXPECT_EQ(end_code_of(r), 0x0401);
    // A port that is not configured: no unit there.
    r = gw.call(scu1_port2, compoway,
                ascii("01000"
                      "0101"
                      "C00000000001"));
    EXPECT_EQ(end_code_of(r), 0x0202);
    // Too short for node, sub-address, SID and command: 1002 at once.
    r = gw.call(scu1_port1, compoway, ascii("0100"));
    EXPECT_EQ(end_code_of(r), 0x1002);
}

}  // namespace
}  // namespace fins::test
