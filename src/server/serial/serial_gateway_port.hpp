// One serial port of a Serial Communications Unit or Board in Serial Gateway mode
// (W342 5-1-1, 5-3-46 .. 5-3-48; frames-serial-files.md 2): it takes already framed
// serial requests (CompoWay/F, Modbus-RTU, Modbus-ASCII, Host Link FINS), sends them one
// at a time in arrival order, waits for the slave's answer within the port's response
// timeout and calls each request's completion exactly once, on the I/O thread.
//
// What the completion receives (frames-serial-files.md 2.4):
//   0000 + the answer's payload (the framing stripped)    the slave answered
//   0000 + nothing                                         a broadcast: nothing to wait for
//   0205 response timeout                                  no (complete) answer in time, or
//                                                          the device cannot be written
//   0206 transmission error                                BCC / CRC / LRC / FCS wrong
//   0204 destination node busy                             max_queued requests already wait
// A late answer (after 0205) is discarded, as the unit does. The port reads the device
// continuously; bytes that arrive while nothing is waiting are dropped.
//
// A port whose device disappears (read or write error, e.g. the other end of a pty
// closed) closes it; each later request tries to open it again (at most once per
// reopen_interval) and gets 0205 while that fails. finsd and its other ports go on.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/serial.hpp"
#include "transport/asio.hpp"
#include "transport/serial_port.hpp"

namespace fins::server {

// How the answer on the line is framed.
enum class SerialFraming : std::uint8_t { compoway_f, modbus_rtu, modbus_ascii, host_link };

struct GatewayPortConfig {
    std::string name;               // "scu1.2", "board.1" (for logs)
    std::uint8_t unit_address = 0;  // 80 + 4N / 81 + 4N, E4 / E5 (W342 5-3-46 tables)
    SerialSettings line;
    // W336 6-6-2: default 5 s, settable 0.1-25.5 s.
    std::chrono::milliseconds timeout{5'000};
    // The FINS network of the Host Link slaves behind the port (W342 5-1-1 "Specifying
    // the Destination PLC's FINS Address"): set when a routing table treats the serial
    // path as a network; without one it is the port's unit address.
    std::optional<std::uint8_t> network;
    [[nodiscard]] std::uint8_t host_link_network() const noexcept {
        return network ? *network : unit_address;
    }
};

// The result a completion receives: the FINS end code and, on 0000, the payload (valid
// only during the call).
using SerialCompletion = std::function<void(EndCode code, Bytes payload)>;
// Host Link framing only: is this whole frame ("@" .. "*" CR) the answer to the job? A
// frame it refuses (an answer to an earlier request: another SID) is dropped and
// counted, and the job keeps waiting within its timeout. Empty: every frame is.
using SerialAnswerCheck = std::function<bool(Bytes frame)>;

class SerialGatewayPort : public std::enable_shared_from_this<SerialGatewayPort> {
  public:
    // W336 6-1-4: up to 5 FINS commands wait for conversion and transmission.
    static constexpr std::size_t max_queued = 5;
    static constexpr std::size_t max_frame = 2'304;
    static constexpr auto reopen_interval = std::chrono::seconds(1);

    struct Counters {
        std::uint64_t answered = 0, timeouts = 0, bad_checksums = 0, busy = 0, late_bytes = 0;
        std::uint64_t foreign_answers = 0;  // Host Link frames the job's check refused
    };

    SerialGatewayPort(asio::io_context& io, GatewayPortConfig config);
    ~SerialGatewayPort();
    SerialGatewayPort(const SerialGatewayPort&) = delete;
    SerialGatewayPort& operator=(const SerialGatewayPort&) = delete;

    // Opens the device and starts reading; the error when it cannot be opened.
    boost::system::error_code open();
    void close();

    // Queues one framed request. `expect_answer` false: complete with 0000 once sent.
    // Over max_queued waiting: completes at once with 0204.
    void submit(SerialFraming framing, Bytes frame, bool expect_answer, SerialCompletion done,
                SerialAnswerCheck is_answer = {});

    [[nodiscard]] const GatewayPortConfig& config() const noexcept { return config_; }
    [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
    [[nodiscard]] bool is_open() const noexcept { return port_.is_open(); }

  private:
    struct Job {
        SerialFraming framing;
        std::vector<std::uint8_t> frame;
        bool expect_answer;
        SerialCompletion done;
        SerialAnswerCheck is_answer;
    };

    void start_next();
    // Every asynchronous completion carries the generation of the job it was started
    // for; a late one (its job already finished: closed, lost, timed out) does nothing.
    void on_written(std::uint64_t generation, boost::system::error_code ec);
    void close_device();
    void read_more();
    void on_read(boost::system::error_code ec, std::size_t n);
    // Looks for the active job's answer in rx_; true when the job finished.
    bool try_answer();
    void finish(EndCode code, Bytes payload);
    void lost(const boost::system::error_code& ec);
    // Silence after a Modbus-RTU answer of unknown length ends it (3.5 characters).
    [[nodiscard]] std::chrono::microseconds rtu_silence() const noexcept;

    asio::io_context& io_;
    GatewayPortConfig config_;
    transport::SerialPort port_;
    asio::steady_timer timer_;    // the response timeout
    asio::steady_timer silence_;  // Modbus-RTU end of frame
    std::deque<Job> queue_;       // front() is active when active_
    bool active_ = false;
    bool reading_ = false;
    std::uint64_t opened_ = 0;      // counts opens; tells a stale read from the open device's
    std::uint64_t generation_ = 0;  // the active job's; tells a stale completion from its
    std::chrono::steady_clock::time_point last_open_attempt_{};
    std::array<std::uint8_t, 512> read_buffer_{};
    std::vector<std::uint8_t> rx_;  // bytes of the active job's answer so far
    Counters counters_;
};

}  // namespace fins::server
