// SerialGatewayPort on an openpty() pair, the test playing the slave byte by byte: the
// answer is found in split input, bytes while nothing waits are dropped (a late answer,
// W336 6-6-2), Modbus-RTU
// answers of unknown length end with the silence, bad CRC / LRC are 0206, requests run
// in order and each completes once.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <pty.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "fins/modbus.hpp"
#include "server/serial/serial_gateway_port.hpp"
#include "transport/asio.hpp"

namespace fins::server {
namespace {

using namespace std::chrono_literals;

struct Result {
    bool done = false;
    EndCode code = EndCode::normal_completion;
    std::vector<std::uint8_t> payload;
};

class PortTest : public ::testing::Test {
  protected:
    void SetUp() override {
        char name[64] = {};
        ASSERT_EQ(::openpty(&master_, &slave_, name, nullptr, nullptr), 0);
        GatewayPortConfig c;
        c.name = "test";
        c.unit_address = 0x80;
        c.line.device = name;
        c.line.data_bits = 8;
        c.timeout = 300ms;
        port_ = std::make_shared<SerialGatewayPort>(io_, c);
        ASSERT_FALSE(port_->open());
    }
    void TearDown() override {
        port_->close();
        io_.run_for(50ms);
        ::close(master_);
        ::close(slave_);
    }
    void submit(SerialFraming framing, const std::vector<std::uint8_t>& frame, Result& r) {
        port_->submit(framing, frame, true, [&r](EndCode code, Bytes payload) {
            EXPECT_FALSE(r.done) << "completed twice";
            r.done = true;
            r.code = code;
            r.payload.assign(payload.begin(), payload.end());
        });
    }
    // What the port wrote on the line, read by the "slave".
    std::vector<std::uint8_t> line_read() {
        for (int i = 0; i < 100; ++i) {
            io_.run_for(5ms);
            std::vector<std::uint8_t> buf(512);
            ::fcntl(master_, F_SETFL, O_NONBLOCK);
            const auto n = ::read(master_, buf.data(), buf.size());
            if (n > 0) {
                buf.resize(static_cast<std::size_t>(n));
                return buf;
            }
        }
        return {};
    }
    void line_write(const std::vector<std::uint8_t>& bytes) {
        ASSERT_EQ(::write(master_, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
    }
    void run_until(const Result& r) {
        for (int i = 0; i < 400 && !r.done; ++i)
            io_.run_for(5ms);
    }

    asio::io_context io_;
    int master_ = -1;
    int slave_ = -1;
    std::shared_ptr<SerialGatewayPort> port_;
};

std::vector<std::uint8_t> rtu(std::vector<std::uint8_t> pdu) {
    std::vector<std::uint8_t> out(pdu.size() + 2);
    ByteWriter w(out);
    modbus::write_rtu_frame(w, pdu);
    return out;
}

TEST_F(PortTest, RtuAnswerSplitAcrossWritesIsFound) {
    Result r;
    submit(SerialFraming::modbus_rtu, rtu({0x01, 0x03, 0x00, 0x00, 0x00, 0x01}), r);
    EXPECT_EQ(line_read(), rtu({0x01, 0x03, 0x00, 0x00, 0x00, 0x01}));
    const auto answer = rtu({0x01, 0x03, 0x02, 0x12, 0x34});
    line_write({answer.begin(), answer.begin() + 3});
    io_.run_for(20ms);
    EXPECT_FALSE(r.done);
    line_write({answer.begin() + 3, answer.end()});
    run_until(r);
    ASSERT_TRUE(r.done);
    EXPECT_EQ(r.code, EndCode::normal_completion);
    EXPECT_EQ(r.payload, (std::vector<std::uint8_t>{0x01, 0x03, 0x02, 0x12, 0x34}));
}

TEST_F(PortTest, RtuUnknownFunctionEndsWithSilenceAndBadCrcIs0206) {
    Result r;
    submit(SerialFraming::modbus_rtu, rtu({0x01, 0x2B, 0x0E, 0x01, 0x00}), r);
    line_read();
    line_write(rtu({0x01, 0x2B, 0x0E, 0x01, 0x01}));
    run_until(r);
    EXPECT_EQ(r.code, EndCode::normal_completion);
    EXPECT_EQ(r.payload.size(), 5U);

    Result bad;
    submit(SerialFraming::modbus_rtu, rtu({0x01, 0x06, 0x00, 0x01, 0x00, 0x02}), bad);
    line_read();
    auto answer = rtu({0x01, 0x06, 0x00, 0x01, 0x00, 0x02});
    answer.back() ^= 0xFF;
    line_write(answer);
    run_until(bad);
    EXPECT_EQ(bad.code, EndCode::transmission_error);
}

TEST_F(PortTest, W336_6_6_2_TimeoutThenTheNextInOrderAndIdleBytesDropped) {
    Result first;
    Result second;
    const std::string a = ":01030000000AF2\r\n";
    submit(SerialFraming::modbus_ascii, {a.begin(), a.end()}, first);
    submit(SerialFraming::modbus_ascii, {a.begin(), a.end()}, second);
    line_read();
    run_until(first);
    EXPECT_EQ(first.code, EndCode::response_timeout);
    EXPECT_FALSE(second.done);  // in order: the second goes out after the first ended
    // The first request's late answer arrives while the second waits: it is the
    // second's answer on the line, as on a real port; the test sends a bad LRC to tell
    // them apart, then nothing: a late byte stream never completes a request twice.
    line_read();
    const std::string bad = ":0103020001F0\r\n";
    line_write({bad.begin(), bad.end()});
    run_until(second);
    EXPECT_EQ(second.code, EndCode::transmission_error);
    // Bytes while nothing waits are dropped.
    line_write({bad.begin(), bad.end()});
    io_.run_for(30ms);
    EXPECT_GT(port_->counters().late_bytes, 0U);
}

TEST_F(PortTest, W336_6_1_4_SixthWaitingRequestIsBusy) {
    std::vector<Result> results(SerialGatewayPort::max_queued + 2);
    const std::string a = ":01030000000AF2\r\n";
    for (auto& r : results)
        submit(SerialFraming::modbus_ascii, {a.begin(), a.end()}, r);
    EXPECT_TRUE(results.back().done);
    EXPECT_EQ(results.back().code, EndCode::destination_node_busy);
    for (std::size_t i = 0; i + 1 < results.size(); ++i)
        EXPECT_FALSE(results[i].done);
    // Closing the port completes whatever still waits (0205), exactly once each.
    port_->close();
    for (std::size_t i = 0; i + 1 < results.size(); ++i) {
        EXPECT_TRUE(results[i].done);
        EXPECT_EQ(results[i].code, EndCode::response_timeout);
    }
}

// Every completion belongs to its job (W336 6-1-4: one request at a time on the line):
// the write of a request that was ended meanwhile (the port closed and opened again)
// completes late, after the next request started; it must not act on that one (before:
// its "operation aborted" made the port drop the next request with 0205 and close).
TEST_F(PortTest, W336_6_1_4_LateWriteCompletionOfAnEndedJobDoesNotTouchTheNext) {
    // Fill the line so that the first request's write cannot finish at once.
    ::fcntl(slave_, F_SETFL, O_NONBLOCK);
    const std::vector<std::uint8_t> filler(4096, 0x55);
    std::size_t filled = 0;
    for (int i = 0; i < 10'000; ++i) {
        const auto n = ::write(slave_, filler.data(), filler.size());
        if (n <= 0) break;
        filled += static_cast<std::size_t>(n);
    }
    ASSERT_GT(filled, 0U);
    Result first;
    const auto request = rtu({0x01, 0x03, 0x00, 0x00, 0x00, 0x01});
    submit(SerialFraming::modbus_rtu, request, first);
    port_->close();  // ends the first (0205); its write completes later, aborted
    ASSERT_TRUE(first.done);
    EXPECT_EQ(first.code, EndCode::response_timeout);
    ASSERT_FALSE(port_->open());
    Result second;
    submit(SerialFraming::modbus_rtu, request, second);
    // Drain the line until the second request is on it, then answer it.
    std::vector<std::uint8_t> line;
    ::fcntl(master_, F_SETFL, O_NONBLOCK);
    for (int i = 0; i < 400 && !second.done; ++i) {
        io_.run_for(5ms);
        std::array<std::uint8_t, 4096> buf{};
        for (int reads = 0; reads < 64; ++reads) {
            const auto n = ::read(master_, buf.data(), buf.size());
            if (n <= 0) break;
            line.insert(line.end(), buf.begin(), buf.begin() + n);
        }
        if (line.size() >= request.size() &&
            std::equal(request.begin(), request.end(),
                       line.end() - static_cast<long>(request.size())))
            break;
    }
    ASSERT_FALSE(second.done) << "ended by the first request's write";
    line_write(rtu({0x01, 0x03, 0x02, 0x12, 0x34}));
    run_until(second);
    ASSERT_TRUE(second.done);
    EXPECT_EQ(second.code, EndCode::normal_completion);
    EXPECT_TRUE(port_->is_open());
}

}  // namespace
}  // namespace fins::server
