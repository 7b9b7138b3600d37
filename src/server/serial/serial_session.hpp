// finsd as a Host Link slave (W342 3-5; fins-frames.md section 4): FINS commands in
// Host Link "FA" frames on a serial device, answered through the same Dispatcher as
// UDP and TCP (Link::serial). One request at a time, as on a real half-duplex line.
//
//   read -> scan_host_link (frame finder) -> decode_host_link -> Dispatcher::handle
//        -> encode_host_link_response -> (response wait time) -> write
//
// - Frames for another Host Link unit number are ignored (multi-drop line).
// - Frames with a bad FCS, a format error, a non-FINS header code or over 1,114
//   characters get the Host Link error answer "@UUFA" EC FCS "*" CR (13, 14, 16, 18;
//   docs/serial.md "Host Link (serial)"); their unit number must be readable and ours.
// - Garbage between frames is skipped; a line with no CR within max_line characters is
//   dropped unanswered (C-mode rule: over-long frames get no response). The receive
//   buffer is fixed: nothing the line sends grows memory.
// - Answers hold at most 538 data bytes: a command whose answer would be longer gets
//   FINS end code 110B (response too long) from the handler.
// - The response wait time digit (10 ms units) delays the answer.
// - The device failing (a pty whose other end closed, an adapter pulled) is logged once;
//   the session closes it and tries to open it again every reopen_interval (doubling up
//   to max_reopen_interval), logging again only when it is back. Ethernet is unaffected.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "fins/host_link.hpp"
#include "fins/serial.hpp"
#include "transport/asio.hpp"
#include "transport/serial_port.hpp"

namespace fins::server {

class Dispatcher;

struct SerialSessionOptions {
    std::string name = "cpu";  // for logs: "serial cpu (/dev/ttyUSB0): ..."
    SerialSettings line;
    std::uint8_t unit = 0;  // Host Link unit number 0-31
    std::chrono::milliseconds reopen_interval{500};
    std::chrono::milliseconds max_reopen_interval{10'000};
};

class SerialSession : public std::enable_shared_from_this<SerialSession> {
  public:
    // Characters kept while waiting for a CR; longer lines are dropped.
    static constexpr std::size_t max_line = 2048;

    struct Counters {
        std::uint64_t frames = 0;      // frames for this unit
        std::uint64_t answered = 0;    // FINS answers written
        std::uint64_t errors = 0;      // Host Link error answers written
        std::uint64_t other_unit = 0;  // frames for another unit number, ignored
        std::uint64_t skipped = 0;     // garbage bytes and over-long lines dropped
        std::uint64_t opens = 0;       // successful opens of the device
    };

    SerialSession(asio::io_context& io, Dispatcher& dispatcher, SerialSessionOptions options);
    ~SerialSession();
    SerialSession(const SerialSession&) = delete;
    SerialSession& operator=(const SerialSession&) = delete;

    // Opens the device; when that fails, logs it and keeps trying (see above). Returns
    // whether the first open worked.
    bool start();
    void close();
    [[nodiscard]] bool is_open() const noexcept { return port_.is_open(); }
    [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
    [[nodiscard]] const SerialSessionOptions& options() const noexcept { return options_; }

  private:
    bool open();
    void lost(boost::system::error_code ec);
    void schedule_reopen();
    void receive();
    void on_bytes(std::size_t n);
    void on_frame(Bytes frame);
    void reply(std::size_t size, std::uint8_t wait);
    void write();

    Dispatcher& dispatcher_;
    SerialSessionOptions options_;
    transport::SerialPort port_;
    asio::steady_timer timer_;  // reopen back-off, or the response wait time
    std::chrono::milliseconds backoff_{};
    bool stopped_ = false;
    bool failure_logged_ = false;
    bool busy_ = false;  // an answer is waiting or being written: the line is ours
    std::uint64_t generation_ = 0;
    Counters counters_;
    std::array<std::uint8_t, max_line + 512> rx_{};
    std::size_t rx_size_ = 0;
    std::array<std::uint8_t, host_link_max_fins_response> fins_in_{};
    std::array<std::uint8_t, host_link_max_fins_response> fins_out_{};
    std::array<std::uint8_t, host_link_max_response_chars> tx_{};
    std::size_t tx_size_ = 0;
};

}  // namespace fins::server
