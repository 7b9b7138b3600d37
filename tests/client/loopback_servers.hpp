// In-test FINS servers on loopback (raw asio, port 0), each on its own thread with its
// own io_context, answering through FakePlc. The test thread reads their state through
// locked accessors and waits with a bounded condition-variable wait, never a sleep.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>

#include "client/fake_plc.hpp"
#include "transport/asio.hpp"

namespace fins::test {

using namespace std::chrono_literals;

// What both servers share: the PLC, the log of request frames, the wait.
class ServerBase {
  public:
    ServerBase();
    virtual ~ServerBase();
    ServerBase(const ServerBase&) = delete;
    ServerBase& operator=(const ServerBase&) = delete;

    // Every request frame received, in order.
    std::vector<std::vector<std::uint8_t>> requests();
    // Waits (bounded) until at least n request frames have arrived.
    bool wait_for_requests(std::size_t n, std::chrono::milliseconds limit = 5s);
    // Runs f on the PLC under the server's lock.
    void with_plc(const std::function<void(FakePlc&)>& f);

  protected:
    void start_thread();
    void stop_thread();
    // Records a request and returns the PLC's answer (called on the server thread).
    std::vector<std::uint8_t> record_and_handle(Bytes frame);

    asio::io_context io_;
    std::mutex mutex_;
    std::condition_variable changed_;
    FakePlc plc_;
    std::vector<std::vector<std::uint8_t>> requests_;

  private:
    std::thread thread_;
};

class UdpResponder : public ServerBase {
  public:
    // Binds `address` port 0; check ok() (false e.g. when ::1 is unavailable).
    explicit UdpResponder(const std::string& address = "127.0.0.1");
    ~UdpResponder() override;

    [[nodiscard]] bool ok() const noexcept { return ok_; }
    [[nodiscard]] std::uint16_t port() const noexcept { return port_; }
    // Collect n requests, then answer them all in reverse order (0 = answer at once).
    void hold_until(std::size_t n);
    void set_silent(bool silent);        // never answer
    void set_duplicate(bool duplicate);  // send every answer twice
    // Waits (bounded) until at least n answers have been handed to the kernel.
    bool wait_for_answers(std::size_t n, std::chrono::milliseconds limit = 5s);

  private:
    void receive();

    asio::ip::udp::socket socket_;
    asio::ip::udp::endpoint peer_;
    std::array<std::uint8_t, 4096> buffer_{};
    std::vector<std::vector<std::uint8_t>> held_;
    std::size_t hold_ = 0;
    bool silent_ = false;
    bool duplicate_ = false;
    std::size_t answers_sent_ = 0;
    bool ok_ = false;
    std::uint16_t port_ = 0;
};

struct TcpBehaviour {
    enum class Mode {
        normal,           // one write per answer
        split,            // each answer in two writes, split at the next byte position
        glue,             // answers written two per write
        drop_first,       // close the first connection on its first frame, then normal
        frame_error,      // answer the first frame with command 3, close, then normal
        handshake_error,  // answer every handshake with command 1 carrying `error`
        confirm,          // put a command 6 (connection confirmation) before every answer
        unknown_command,  // answer the first frame with a packet of command 0x99
        mute,             // accept connections, never answer anything
    };
    Mode mode = Mode::normal;
    std::uint32_t error = 0x21;
    std::uint8_t server_node = 10;
    std::uint8_t allocated_node = 0x22;  // given when the client asks for node 0
};

class TcpResponder : public ServerBase {
  public:
    explicit TcpResponder(TcpBehaviour behaviour = {}, const std::string& address = "127.0.0.1");
    ~TcpResponder() override;

    [[nodiscard]] bool ok() const noexcept { return ok_; }
    [[nodiscard]] std::uint16_t port() const noexcept { return port_; }
    // Handshakes answered, and the client node each one asked for.
    std::vector<std::uint8_t> handshakes();
    // Answers written split in two (the split position cycles through 1 .. size-1). Two
    // writes may still reach the client as one read: this counts what the server did.
    std::size_t split_answers();
    // Closes every accepted connection, as a restarting finsd does, and returns once the
    // sockets are closed (their FIN is on its way); the listener keeps accepting.
    bool drop_connections(std::chrono::milliseconds limit = 5s);
    // Error codes of the command-3 packets the client sent; waits (bounded) for n.
    std::vector<std::uint32_t> envelope_errors(std::size_t n = 0,
                                               std::chrono::milliseconds limit = 5s);

    struct Session;

  private:
    void accept();
    friend struct Session;

    TcpBehaviour behaviour_;
    asio::ip::tcp::acceptor acceptor_;
    std::vector<std::shared_ptr<Session>> sessions_;
    std::vector<std::uint8_t> handshakes_;
    std::vector<std::uint32_t> envelope_errors_;
    std::size_t next_split_ = 1;
    std::size_t split_answers_ = 0;
    bool dropped_ = false;
    bool ok_ = false;
    std::uint16_t port_ = 0;
};

}  // namespace fins::test
