// `fins modbus` against finsd's Serial Gateway with real slaves on a socat pty pair:
// libmodbus's RTU slave (28 04) and pymodbus's ASCII framer (28 05), as in
// serial_gateway_test.cpp. Values, --json, exception responses (exit 4), usage errors
// (exit 2), and a silent slave reaching the user as the port's 0205 with every default.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"
#include "integration/support/process.hpp"
#include "integration/support/pty_pair.hpp"

namespace fins::test {
namespace {

const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";
const std::string rtu_slave = std::string(FINS_BIN_DIR) + "/fins_test_modbus_slave";

RunResult fins(const Finsd& finsd, std::vector<std::string> args) {
    std::vector<std::string> argv{fins_bin, "--port", std::to_string(finsd.port())};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

nlohmann::json json(const Finsd& finsd, std::vector<std::string> args, int expected_exit = 0) {
    args.push_back("--json");
    const auto r = fins(finsd, args);
    EXPECT_EQ(r.exit_code, expected_exit) << r.out << r.err;
    return nlohmann::json::parse(r.out, nullptr, false);
}

// finsd with gateway port scu1.2 (unit address 85) on a pty whose other end has the
// libmodbus RTU slave 1: holding register n holds n, input register n 1000 + n.
class CliModbus : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!std::filesystem::exists(rtu_slave))
            GTEST_SKIP() << "libmodbus-dev was not found at configure time";
        ASSERT_TRUE(line_.ok());
        slave_ = std::make_unique<Child>(std::vector<std::string>{rtu_slave, line_.b(), "1"});
        ASSERT_EQ(slave_->read_line(), "ready");
        finsd_ = std::make_unique<Finsd>(
            std::vector<std::string>{"--serial", "scu1.2=" + line_.a() + ",data=8,stop=1"});
        ASSERT_TRUE(finsd_->started()) << finsd_->result().err;
    }
    RunResult modbus(std::vector<std::string> args) {
        args.insert(args.begin(), "modbus");
        args.insert(args.end(), {"--gateway", "scu1.2"});
        return fins(*finsd_, args);
    }
    nlohmann::json modbus_json(std::vector<std::string> args, int expected_exit = 0) {
        args.insert(args.begin(), "modbus");
        args.insert(args.end(), {"--gateway", "scu1.2"});
        return json(*finsd_, args, expected_exit);
    }

    PtyPair line_;
    std::unique_ptr<Child> slave_;
    std::unique_ptr<Finsd> finsd_;
};

TEST_F(CliModbus, W342_5_3_47_ReadsAndWritesHoldingRegisters) {
    const auto read = modbus({"read", "holding", "4", "2"});
    EXPECT_EQ(read.exit_code, 0) << read.err;
    EXPECT_EQ(read.out, "holding 4  4\nholding 5  5\n");

    const auto one = modbus({"write", "holding", "7", "0x1234"});  // 06
    EXPECT_EQ(one.exit_code, 0) << one.err;
    EXPECT_EQ(one.out, "wrote 1 register at holding 7 of slave 1\n");
    const auto several = modbus_json({"write", "holding", "10", "1", "2", "65535"});  // 10
    EXPECT_EQ(several["written"], 3);
    EXPECT_EQ(several["slave"], 1);
    const auto back = modbus_json({"read", "holding", "7", "6"});
    EXPECT_EQ(back["table"], "holding");
    EXPECT_EQ(back["start"], 7);
    EXPECT_EQ(back["values"], (nlohmann::json{0x1234, 8, 9, 1, 2, 65535}));
}

TEST_F(CliModbus, W342_5_3_47_CoilsDiscreteInputsAndInputRegisters) {
    EXPECT_EQ(modbus_json({"write", "coils", "3", "1", "0", "1"})["written"], 3);  // 0F
    EXPECT_EQ(modbus_json({"write", "coils", "9", "1"})["written"], 1);            // 05
    EXPECT_EQ(modbus_json({"read", "coils", "0", "10"})["values"],
              (nlohmann::json{0, 0, 0, 1, 0, 1, 0, 0, 0, 1}));
    EXPECT_EQ(modbus_json({"read", "discrete", "0", "3"})["values"], (nlohmann::json{0, 0, 0}));
    EXPECT_EQ(modbus_json({"read", "input", "2", "2"})["values"], (nlohmann::json{1002, 1003}));
}

// An exception response is a normal 0000 FINS answer (W342 5-3-47 "the same as the
// command"); fins names the exception and exits 4, as for a refusing PLC.
TEST_F(CliModbus, W342_5_3_47_ExceptionResponseExits4WithItsName) {
    const auto r = modbus({"read", "holding", "100"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("slave 1 answered exception 02 (ILLEGAL DATA ADDRESS)"), std::string::npos)
        << r.err;
    const auto doc = modbus_json({"read", "holding", "100"}, 4);
    EXPECT_EQ(doc["error"]["kind"], "modbus_exception");
    EXPECT_EQ(doc["error"]["exception"], 2);
}

TEST_F(CliModbus, BadArgumentsAreUsageErrorsBeforeAnythingIsSent) {
    for (const auto& args : std::vector<std::vector<std::string>>{
             {"write", "input", "0", "1"},              // read-only table
             {"write", "discrete", "0", "1"},           // read-only table
             {"write", "coils", "0", "2"},              // a coil is 0 or 1
             {"write", "holding", "0", "65536"},        // past a register
             {"read", "holding", "0", "126"},           // 125 registers per read
             {"read", "coils", "0", "2001"},            // 2000 bits per read
             {"read", "holding", "65535", "2"},         // past address 65535
             {"read", "holding", "0", "--slave", "0"},  // a broadcast gets no answer
             {"read", "holding", "0", "--slave", "248"},
             {"read", "registers", "0"},
             {"peek", "holding", "0"},
             {"read", "holding", "0", "--gateway", "scu16.1"},
             {"read", "holding", "0", "--gateway", "scu1.3"},
             {"read", "holding", "0", "--gateway", "185"},
         }) {
        const auto r = modbus(args);
        EXPECT_EQ(r.exit_code, 2) << args[0] << " " << args[1] << ": " << r.err;
    }
    // Without --gateway or a --dest naming a unit, 28 04 would reach the CPU Unit.
    const auto r = fins(*finsd_, {"modbus", "read", "holding", "0"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--gateway scu1.2"), std::string::npos) << r.err;
}

// The port's unit address (W342 5-3-47 tables: scu1.2 is 85 hex) reaches the same port,
// in --gateway as the tables print it (hex) or in --dest.
TEST_F(CliModbus, W342_5_3_47_GatewayOrDestByThePortUnitAddress) {
    for (const auto& how : std::vector<std::vector<std::string>>{
             {"--dest", "0.0.0x85"}, {"--gateway", "85"}, {"--gateway", "0x85"}}) {
        std::vector<std::string> args{"modbus", "read", "holding", "3"};
        args.insert(args.end(), how.begin(), how.end());
        const auto r = fins(*finsd_, args);
        EXPECT_EQ(r.exit_code, 0) << how[1] << ": " << r.err;
        EXPECT_EQ(r.out, "holding 3  3\n") << how[1];
    }
}

// W342 5-3-47 names no timeout; W336 6-6-2 gives the port one, W596 p. 3-16 gives fins 2 s.
// With both defaults (no --timeout, no timeout=) a silent slave must come back as the
// port's 0205, not as fins giving up first (exit 3, "no response").
TEST(CliModbusDefaults, W342_5_3_47_SilentSlaveIsThePorts0205WithBothDefaults) {
    PtyPair line;  // nobody on the other end
    ASSERT_TRUE(line.ok());
    Finsd finsd({"--serial", "scu1.1=" + line.a()});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    const auto doc =
        json(finsd, {"modbus", "read", "holding", "0", "--slave", "9", "--gateway", "scu1.1"}, 4);
    EXPECT_EQ(doc["error"]["kind"], "end_code");
    EXPECT_EQ(doc["error"]["end_code"], "0205");
    EXPECT_NE(doc["error"]["hint"].get<std::string>().find("slave 9 did not answer"),
              std::string::npos);
}

// A port finsd does not have answers 0202 (W342 5-1-3): fins says which port is missing
// instead of the generic "the CPU Unit is unit 0".
TEST_F(CliModbus, W342_5_3_47_MissingPortIs0202WithAHintAboutThePort) {
    const auto r = fins(*finsd_, {"modbus", "read", "holding", "0", "--gateway", "scu2.1"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("fins: modbus read holding 0: the PLC answered unit missing"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("no Serial Gateway port at scu2.1"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("unit 0"), std::string::npos) << r.err;
    const auto doc = json(*finsd_, {"modbus", "read", "holding", "0", "--gateway", "scu2.1"}, 4);
    EXPECT_EQ(doc["error"]["end_code"], "0202");
    EXPECT_EQ(doc["error"]["name"], "unit missing");
}

TEST(CliModbusAscii, W342_5_3_48_ReadsAndWritesThroughModbusAscii) {
    if (!std::filesystem::exists("/usr/bin/python3"))
        GTEST_SKIP() << "Debian's python3 (with python3-pymodbus) is not installed";
    PtyPair line;
    ASSERT_TRUE(line.ok());
    Child slave({"/usr/bin/python3",
                 std::string(FINS_SOURCE_DIR) + "/tests/tools/modbus_ascii_slave.py", line.b(),
                 "2"});
    if (slave.read_line(std::chrono::seconds(20)) != "ready")
        GTEST_SKIP() << "pymodbus slave did not start (python3-pymodbus missing?)";
    Finsd finsd({"--serial", "scu1.2=" + line.a() + ",data=8,stop=1"});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    const std::vector<std::string> port{"--ascii", "--slave", "2", "--gateway", "scu1.2"};
    const auto with_port = [&](std::vector<std::string> args) {
        args.insert(args.begin(), "modbus");
        args.insert(args.end(), port.begin(), port.end());
        return args;
    };
    EXPECT_EQ(json(finsd, with_port({"read", "holding", "4", "2"}))["values"],
              (nlohmann::json{4, 5}));
    EXPECT_EQ(json(finsd, with_port({"write", "holding", "7", "4660"}))["written"], 1);
    EXPECT_EQ(json(finsd, with_port({"read", "holding", "7"}))["values"], (nlohmann::json{4660}));
    const auto refused = json(finsd, with_port({"read", "holding", "100", "5"}), 4);
    EXPECT_EQ(refused["error"]["kind"], "modbus_exception");
}

}  // namespace
}  // namespace fins::test
