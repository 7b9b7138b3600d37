// FINS over Host Link, client side (W342 3-5; fins-frames.md section 4): binary FINS
// frames from the request tracker go out as Host Link "FA" command frames on a serial
// port; Host Link responses come back as binary FINS frames.
//
// - Form: the direct form (ICF 00, DA2 SA2 SID) while the frame's DNA, DA1, SNA and SA1
//   are all 00 (the directly connected CPU Unit), otherwise the network form with the
//   whole header.
// - Half duplex: the tracker keeps one request on the line at a time (the client sets
//   its window to 1); frames handed over meanwhile (retransmissions, no-response
//   frames) wait here, in order, and each is written whole.
// - Answers: the frame finder (scan_host_link) over a fixed buffer; garbage between
//   frames and over-long lines are skipped. An answer from another unit number is
//   ignored (another slave on a multi-drop line). An answer with a Host Link end code
//   other than 00 goes to the error handler as a HostLinkEndCode; an answer with a bad
//   FCS or that is no FINS response as a HostLinkError. The client then fails the request
//   on the line with that error.
// - The port closing under us (a pty whose other end went away, a USB adapter pulled)
//   closes the transport: requests fail with ClientError::connection_closed and the next
//   request opens the device again.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include <boost/asio/io_context.hpp>

#include "fins/host_link.hpp"
#include "fins/serial.hpp"
#include "transport/asio.hpp"
#include "transport/serial_port.hpp"
#include "transport/transport.hpp"
#include "transport/write_queue.hpp"

namespace fins::transport {

struct HostLinkOptions {
    SerialSettings line;
    std::uint8_t unit = 0;  // Host Link unit number 0-31
    std::uint8_t wait = 0;  // response wait time digit, 10 ms units (0 = answer at once)
};

class HostLinkTransport final : public Transport {
  public:
    HostLinkTransport(asio::io_context& io, HostLinkOptions options);
    ~HostLinkTransport() override;

    void async_open(OpenHandler done) override;
    void send(Bytes frame) override;
    void close() override;
    [[nodiscard]] State state() const noexcept override { return state_; }
    [[nodiscard]] bool write_pending() const noexcept override { return !queue_.empty(); }
    [[nodiscard]] bool peer_gone() override { return false; }

  private:
    void receive();
    void on_bytes(std::size_t n);
    void on_frame(Bytes frame);
    void write_next();
    void fail(boost::system::error_code reason);

    asio::io_context& io_;
    HostLinkOptions options_;
    SerialPort port_;
    State state_ = State::closed;
    std::uint64_t generation_ = 0;
    std::shared_ptr<int> life_ = std::make_shared<int>(0);
    WriteQueue queue_;
    bool writing_ = false;
    // Unconsumed received characters: up to one whole response plus one read.
    std::array<std::uint8_t, host_link_max_response_chars + 512> rx_{};
    std::size_t rx_size_ = 0;
    std::array<std::uint8_t, host_link_max_command_chars> tx_{};
    std::array<std::uint8_t, host_link_max_fins_response> fins_{};
};

}  // namespace fins::transport
