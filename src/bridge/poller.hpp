// One PLC's poller: asynchronous FINS over UDP or FINS/TCP on the bridge's io_context,
// built from libfins' codec (frames, service IDs, end codes) rather than the synchronous
// fins::Client, so that one thread polls a thousand PLCs.
//
// - Groups: each group has a drift-free timer (tick k at start + phase + k x interval;
//   phases spread over the interval across all groups of the bridge). A tick that finds
//   the previous cycle of its group still running is skipped and counted as an overrun;
//   nothing is queued.
// - Window: at most Plc::window frames in flight; the rest of a cycle waits in a queue
//   bounded by the group's frame count (one cycle per group at a time) plus
//   max_pending_writes writes.
// - Answers (request_window.hpp): matched by service ID, source node and command code; a
//   SID is not reused for 2 x timeout after its frame was answered or given up, so a late
//   or duplicated answer never completes another request. An answer that matches but for
//   its source node is dropped too, counted, and the PLC's offline status then names
//   both nodes and the `dest` to configure instead of a bare timeout.
// - Timeouts: a frame unanswered after Plc::timeout is sent again with a new service ID
//   (Plc::retries times); then it fails with ClientError::timeout and the PLC is offline.
// - Offline: every queued frame fails at once, writes are refused, the status says
//   offline with the last error, and a probe (UDP: the first frame of the first group;
//   TCP: connect and the node-address handshake) is tried after a back-off with full
//   jitter: uniform(0, min(backoff_max, backoff_min x 2^attempt)).
// - A tag whose frame failed carries the error (end code or timeout), never a value.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "bridge/config.hpp"
#include "bridge/payload.hpp"
#include "bridge/plan.hpp"
#include "bridge/poll_schedule.hpp"
#include "bridge/request_window.hpp"
#include "fins/frame.hpp"
#include "transport/asio.hpp"

namespace fins::bridge {

inline constexpr std::size_t max_pending_writes = 16;  // per PLC; more are refused at once

struct PollerStats {
    std::uint64_t cycles = 0;     // completed group cycles
    std::uint64_t values = 0;     // tag values read successfully
    std::uint64_t frames = 0;     // frames answered
    std::uint64_t overruns = 0;   // ticks skipped: the previous cycle was still running
    std::uint64_t timeouts = 0;   // frames that failed after every retry
    std::uint64_t resends = 0;    // frames sent again after a timeout
    std::uint64_t end_codes = 0;  // frames answered with an error end code
    // Answers with the SID and command of a frame in flight but from another node than
    // the one it went to: dropped (they are not the addressed PLC's), counted and reported.
    std::uint64_t other_node_answers = 0;
};

// What a poller reports; implemented by the Bridge (bridge.hpp). Called on the
// io_context thread.
class PollerEvents {
  public:
    virtual ~PollerEvents() = default;
    virtual void group_done(const GroupSample& sample) = 0;
    virtual void status_changed(const PlcStatus& status) = 0;
    virtual void write_done(const Plc& plc, const WriteResponse& response) = 0;
};

class PlcPoller {
  public:
    // `phase` in [0, 1): where in its interval each group's first tick falls.
    PlcPoller(asio::io_context& io, const Plc& plc, double phase, PollerEvents& events,
              std::uint64_t seed);
    ~PlcPoller();
    PlcPoller(const PlcPoller&) = delete;
    PlcPoller& operator=(const PlcPoller&) = delete;

    void start();
    // Stops polling and closes the socket; queued writes are answered with an error.
    void stop();
    [[nodiscard]] bool running() const noexcept { return running_; }
    [[nodiscard]] bool online() const noexcept { return state_ == State::online; }
    [[nodiscard]] const Plc& plc() const noexcept { return plc_; }
    // The node its frames go to (dest, the IP's last number, or the TCP handshake's).
    [[nodiscard]] const NodeAddress& destination() const noexcept { return destination_; }
    [[nodiscard]] const PollerStats& stats() const noexcept { return stats_; }
    // The next cycle of every group publishes all its tags (after an MQTT reconnect: what
    // was published while disconnected was dropped).
    void request_full() noexcept;

    // Queues a write of `value` (already type- and range-checked) to `tag`, then a read
    // back. The answer comes through PollerEvents::write_done. Returns an error text
    // (and queues nothing) when the PLC is offline or max_pending_writes are waiting.
    std::optional<std::string> write(const Tag& tag, const Encoded& value, std::string id);

  private:
    enum class State : std::uint8_t { stopped, connecting, online, offline };
    struct GroupState;

    void open();
    void tcp_connect();
    void tcp_read();
    void tcp_flush();
    void udp_read();
    void on_frame(Bytes frame);
    void tick(std::size_t group);
    void schedule(std::size_t group);
    void enqueue(Request r);
    void pump();
    bool send(Request& r);
    void arm_timeout();
    void on_timeout();
    void complete(Request& r, const ResponseView* response, std::error_code error);
    void finish_group(std::size_t group);
    void write_answered(Request& r, const ResponseView* response, std::error_code failure);
    void finish_write(PendingWrite& op, std::error_code error, const ResponseView* response);
    void send_write(PendingWrite& op);
    void go_online();
    void go_offline(std::error_code why);
    std::string other_node_text() const;
    void close_socket();
    void backoff();
    std::int64_t now_ms() const;

    asio::io_context& io_;
    const Plc& plc_;
    double phase_;
    PollerEvents& events_;
    State state_ = State::stopped;
    bool running_ = false;
    std::uint64_t generation_ = 0;         // handlers of an older start/connection return early
    std::uint64_t socket_generation_ = 0;  // bumped when the socket closes
    std::optional<std::chrono::steady_clock::time_point> armed_;  // the timeout timer's wait

    asio::ip::udp::socket udp_;
    asio::ip::tcp::socket tcp_;
    std::optional<asio::ip::udp::endpoint> udp_peer_;
    std::optional<asio::ip::tcp::endpoint> tcp_peer_;
    NodeAddress destination_;
    NodeAddress source_;
    std::array<std::uint8_t, 2048 + 16> rx_{};
    std::size_t rx_used_ = 0;
    std::vector<std::uint8_t> tx_;       // TCP: packets waiting for the socket
    std::vector<std::uint8_t> tx_busy_;  // TCP: the packets being written
    bool writing_ = false;
    std::array<std::uint8_t, max_frame_size + 16> scratch_{};

    std::vector<std::unique_ptr<GroupState>> groups_;
    std::deque<Request> ready_;
    RequestWindow window_;
    std::vector<Request> expired_;  // on_timeout's scratch
    std::deque<std::unique_ptr<PendingWrite>> writes_;
    asio::steady_timer timeout_timer_;
    asio::steady_timer backoff_timer_;
    Backoff backoff_;
    std::string last_error_;
    // Who answered the frames sent to destination_ since the last answer accepted, when
    // that was another node (on_frame).
    std::optional<NodeAddress> answered_by_;
    bool other_node_reported_ = false;  // the offline status published names answered_by_
    PollerStats stats_;
};

}  // namespace fins::bridge
