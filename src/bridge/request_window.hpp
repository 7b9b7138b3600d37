// The in-flight window of one PLC poller and the matching of answers to requests. No
// sockets and no clock of its own: every call that needs the time takes `now`, so the
// tests drive it with an invented clock.
//
// An answer belongs to a request only if it carries the request's service ID (SID), comes
// from the node the request went to and echoes its command code. A SID that was answered,
// timed out or given up is not used again for `quarantine` (and never while in flight):
// a late answer to a frame that was resent with a new SID, or a duplicated datagram,
// then finds nothing in flight and is dropped, instead of completing another request.
// At rates that cycle all 256 SIDs within a quarantine, answered SIDs are reused first
// (oldest first) and a timed-out one only when nothing else is free.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "fins/frame.hpp"

namespace fins::bridge {

using PollClock = std::chrono::steady_clock;

struct PendingWrite;  // poller.cpp: a write command and its read back

struct Request {
    enum class Kind : std::uint8_t { group_frame, write, read_back, probe, handshake };
    Kind kind = Kind::group_frame;
    std::size_t group = 0;
    std::size_t frame = 0;
    PendingWrite* op = nullptr;
    std::uint8_t service_id = 0;
    CommandCode command{};
    unsigned attempts = 0;
    PollClock::time_point deadline{};
};

class RequestWindow {
  public:
    RequestWindow(std::size_t capacity, PollClock::duration quarantine);

    [[nodiscard]] bool full() const noexcept { return in_flight_.size() >= capacity_; }
    [[nodiscard]] bool empty() const noexcept { return in_flight_.empty(); }
    [[nodiscard]] std::size_t size() const noexcept { return in_flight_.size(); }

    // A SID for the next frame: not in flight and out of quarantine, the next in turn
    // after the previous one. If every free SID is in quarantine (more than 256 frames
    // within one quarantine), the one released longest ago by an answer; one that timed
    // out only if no answered one is free.
    std::uint8_t allocate(PollClock::time_point now);
    // Puts a sent request (its SID from allocate) in flight. A handshake has no SID and is
    // never matched by take_answer.
    void add(const Request& r);
    // The request this answer is for, taken out of the window (its SID quarantined), or
    // nullopt: late, duplicated, from another node or another command.
    std::optional<Request> take_answer(const Header& answer, CommandCode command,
                                       std::uint8_t plc_node, PollClock::time_point now);
    // Is this an answer to a request in flight (its SID and command) from a node other
    // than `plc_node`? take_answer refuses it; this tells the poller that the PLC answers
    // under another node address than the one it is sent to (a configuration error).
    [[nodiscard]] bool from_other_node(const Header& answer, CommandCode command,
                                       std::uint8_t plc_node) const noexcept;
    // Moves the requests whose deadline is not after `now` to `out` (SIDs quarantined).
    void take_expired(PollClock::time_point now, std::vector<Request>& out);
    // Moves everything in flight to `out` (the PLC went offline; SIDs quarantined).
    void take_all(PollClock::time_point now, std::vector<Request>& out);
    // Drops the handshake request (the TCP node-address answer came).
    void remove_handshake() noexcept;
    [[nodiscard]] std::optional<PollClock::time_point> earliest_deadline() const noexcept;

  private:
    void release(const Request& r, PollClock::time_point now, bool answered) noexcept;

    std::size_t capacity_;
    PollClock::duration quarantine_;
    std::vector<Request> in_flight_;
    std::array<bool, 256> busy_{};
    std::array<std::optional<PollClock::time_point>, 256> released_{};
    std::array<bool, 256> given_up_{};  // released by a timeout or going offline
    std::uint8_t next_ = 0;
};

}  // namespace fins::bridge
