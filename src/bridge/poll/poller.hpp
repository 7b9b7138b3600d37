// One PLC's poller on libfins' request engine: one fins::Client (UDP or FINS/TCP) per
// PLC, embedded in the bridge's io_context (Client::create), so that one thread polls a
// thousand PLCs and the bridge has no FINS engine of its own (docs/architecture.md, "One
// bridge poll").
//
// - Groups: each group has a drift-free timer (tick k at start + phase + k x interval;
//   phases spread over the interval across all groups of the bridge). A tick that finds
//   the previous cycle of its group still running is skipped and counted as an overrun;
//   nothing is queued.
// - Window: at most Plc::window frames handed to the client at once; the rest of a cycle
//   waits in a queue bounded by the group's frame count (one cycle per group at a time)
//   plus max_pending_writes writes.
// - Answers, SIDs and retries are the client's (include/fins/client.hpp): an answer is
//   matched by SID, command and addresses; a frame unanswered after Plc::timeout is sent
//   again, the same frame with the same SID (W596), Plc::retries times; then it fails
//   with ClientError::timeout and the PLC is offline. An answer from another node than
//   the one addressed is counted by the client (other_node()), and the PLC's offline
//   status then names both nodes and the `dest` to configure instead of a bare timeout.
// - Destination: an explicit `dest` is sent as written, node 0 included (W342: DA1 00 is
//   the local PLC); without one the client derives it (UDP: the IP's last number; TCP:
//   the handshake's server node).
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
#include <boost/asio/steady_timer.hpp>

#include "bridge/config.hpp"
#include "bridge/payload.hpp"
#include "bridge/poll/plan.hpp"
#include "bridge/poll/poll_schedule.hpp"
#include "fins/client.hpp"
#include "fins/frame.hpp"
#include "transport/asio.hpp"

namespace fins::bridge {

inline constexpr std::size_t max_pending_writes = 16;  // per PLC; more are refused at once

struct PendingWrite;  // poller_parts.hpp: a write command and its read back

// One frame of the poller: what to do with its answer. Handed to the client by
// PlcPoller::send; `token` finds it again when the client's completion comes.
struct Request {
    enum class Kind : std::uint8_t { group_frame, write, read_back, probe };
    Kind kind = Kind::group_frame;
    std::size_t group = 0;
    std::size_t frame = 0;
    PendingWrite* op = nullptr;
    CommandCode command{};
    std::uint64_t token = 0;
};

struct PollerStats {
    std::uint64_t cycles = 0;     // completed group cycles
    std::uint64_t values = 0;     // tag values read successfully
    std::uint64_t frames = 0;     // frames answered
    std::uint64_t overruns = 0;   // ticks skipped: the previous cycle was still running
    std::uint64_t timeouts = 0;   // frames that failed after every retry
    std::uint64_t resends = 0;    // frames sent again after a timeout (the client's retries)
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
    [[nodiscard]] NodeAddress destination() const noexcept;
    // The poller's counts with the client's resends and other-node answers.
    [[nodiscard]] PollerStats stats() const noexcept;
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
    void on_answer(std::uint64_t token, const Result<ResponseView>& answer);
    void tick(std::size_t group);
    void schedule(std::size_t group);
    void enqueue(Request r);
    void pump();
    void send(Request r);
    void complete(Request& r, const ResponseView* response, std::error_code error);
    void finish_group(std::size_t group);
    void write_answered(Request& r, const ResponseView* response, std::error_code failure);
    void finish_write(PendingWrite& op, std::error_code error, const ResponseView* response);
    void send_write(PendingWrite& op);
    void go_online();
    void go_offline(std::error_code why);
    std::string other_node_text(const NodeAddress& from) const;
    void backoff();
    std::int64_t now_ms() const;

    asio::io_context& io_;
    const Plc& plc_;
    double phase_;
    PollerEvents& events_;
    State state_ = State::stopped;
    bool running_ = false;
    // Completions and timers of an older start or connection return early.
    std::uint64_t generation_ = 0;

    std::unique_ptr<Client> client_;  // on io_: the PLC's one request engine
    std::vector<std::unique_ptr<GroupState>> groups_;
    std::deque<Request> ready_;       // waiting for a place in the window
    std::vector<Request> in_flight_;  // handed to the client (at most Plc::window)
    std::uint64_t next_token_ = 0;
    std::deque<std::unique_ptr<PendingWrite>> writes_;
    asio::steady_timer backoff_timer_;
    Backoff backoff_;
    std::string last_error_;
    bool other_node_reported_ = false;  // the offline status published names another node
    PollerStats stats_;
};

}  // namespace fins::bridge
