// The client's sans-I/O core: service IDs, request frames, response matching,
// timeouts and retransmission. No sockets and no clock: the I/O layer passes `now`
// into every call, hands received frames to on_frame(), arms one timer for
// next_deadline() and calls on_timer() when it fires.
//
// Contract (W596 section 3, Send/Rcv/SendCmd pp. 3-6..3-16, "Option": isNonResp,
// TimeOut, Retry 0-15):
// - Service IDs (SID): see engine/sid_pool.hpp. A SID whose request was retransmitted,
//   timed out or failed after it was sent is quarantined (ClientOptions::sid_quarantine,
//   by default twice the timeout) so that no late answer can complete a later request;
//   clean SIDs are reused least recently used first. Up to 256 requests (the
//   constructor's capacity) are accepted at once; a request that finds no usable SID
//   waits in a FIFO queue until one leaves quarantine; its clock starts when it is sent.
//   The 257th (capacity + 1st) request fails with ClientError::too_many_in_flight.
// - The request frame is built once, at submit(), into a fixed per-request buffer (the
//   SID and addresses are patched in when it is sent); no allocation per request besides
//   the caller's Completion.
// - A response matches when its SID is in flight, its command code equals the
//   request's, and its addresses are the request's swapped (frames 1.5). A request field
//   sent as 00 (network 00 "local network", node 00 "local node") matches any value,
//   because a responder may report its real network or node there.
//   SID not in flight or a different command code: a stale or duplicate answer (for
//   example the second answer to a retransmitted frame); discarded, counted in
//   stats().stale_discarded. Undecodable frames, frames without the response bit and
//   address mismatches are discarded and counted in stats().invalid_discarded; the
//   request stays in flight. A mismatch that is only the responder's node (SID and
//   command of a request in flight, from another node than the one asked) is counted in
//   stats().other_node_answers as well, and other_node() names that node until an answer
//   matches: the peer is not the node it is addressed as (fins-bridge says so).
// - On timeout the identical frame (same SID) is sent again, up to `retries` times; after
//   the last attempt the request fails with ClientError::timeout. A request's clock
//   starts at submit() while the link is down, and again when it is first sent.
// - No-response mode (ICF bit 0, frames 1.2) is submit_no_response(): the frame is handed
//   to the sink and nothing is kept in flight.
// - Link state: while the link is down, submitted requests are held (built but not sent,
//   no SID; a timeout while held or queued consumes an attempt without sending anything).
//   link_up() makes every SID clean again (a new connection or socket: no old answer
//   reaches it), puts the current addresses into the held frames and sends them. link_down() fails
//   every request, sent or held, with the given error: nothing is re-sent after a reconnect,
//   because a request may already have been executed by the PLC.
// - Completions are never called from inside submit(). They are called after the slot is
//   freed, so a completion may submit again; a completion must not destroy the tracker.
// - Per request (RequestOptions; finsd's network instructions, which reach many nodes by
//   many ways through one tracker): its own destination and source instead of the
//   link's; a tag the sink and the answer check get back; its own SID quarantine. The
//   sink may refuse a request's frame (FrameSink::send_request(): no route, connection
//   not established, the kernel refused the last attempt): that request alone fails with
//   the sink's error, at the next on_timer() (its deadline becomes `now`, so never inside
//   submit()); a refused frame counts as not sent (it cannot be answered). The sink hears
//   of every transmission that timed out (FrameSink::unanswered()). on_frame() may be
//   given an AnswerCheck: it decides, instead of the address rule above, whether an
//   answer with the SID and command code of a request in flight is that request's (the
//   owner knows which way the frame went and how that way rewrote the addresses).
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <system_error>
#include <vector>

#include "engine/sid_pool.hpp"
#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// W596 SendCmd p. 3-16: Option.Retry 0 to 15.
inline constexpr unsigned max_retries = 15;
// W596 SendCmd p. 3-16: Option.TimeOut 0 means 2.0 s, which is also the default.
inline constexpr std::chrono::milliseconds default_timeout{2000};
// One per service ID.
inline constexpr std::size_t max_in_flight = 256;
// Quarantine of a suspect SID, in timeouts (see sid_pool.hpp).
inline constexpr int default_quarantine_timeouts = 2;

struct RequestTiming {
    std::chrono::milliseconds timeout = default_timeout;  // per attempt; <= 0 means 2.0 s
    unsigned retries = 0;                                 // extra attempts, 0-15
};

struct TrackerStats {
    std::uint64_t sent = 0;                // frames handed to the sink for the first time
    std::uint64_t retransmitted = 0;       // frames sent again after a timeout
    std::uint64_t completed = 0;           // responses matched to a request
    std::uint64_t timed_out = 0;           // requests failed with ClientError::timeout
    std::uint64_t failed = 0;              // requests failed by link_down() / cancel_all()
    std::uint64_t stale_discarded = 0;     // SID not in flight, or wrong command code
    std::uint64_t invalid_discarded = 0;   // undecodable, not a response, wrong addresses
    std::uint64_t other_node_answers = 0;  // of those: a request's answer from another node
    std::uint64_t quarantined = 0;         // SIDs put into quarantine
    std::uint64_t waited_for_id = 0;       // requests that had to wait for a usable SID
    std::uint64_t refused = 0;             // requests failed because the sink refused a frame
    std::uint64_t quarantine_raised = 0;   // late answers that made the quarantine longer
};

// Per-request options of submit() and submit_no_response() (see the contract above).
struct RequestOptions {
    std::optional<NodeAddress> destination;  // unset: the link's (link_up())
    std::optional<NodeAddress> source;       // unset: the link's
    // Handed back to FrameSink::send_request(), FrameSink::unanswered() and AnswerCheck.
    std::uintptr_t tag = 0;
    // This request's SID quarantine (engine/sid_pool.hpp); zero: the tracker's.
    std::chrono::nanoseconds quarantine{0};
};

// Where frames go. send_frame() must copy the bytes (the slot buffer is reused) and
// must not call back into the tracker; failures are reported later via link_down().
class FrameSink {
  public:
    virtual void send_frame(Bytes frame) = 0;
    // A request's frame (same rules as send_frame()), with its RequestOptions::tag;
    // `last`: no retry follows if it goes unanswered. An error refuses the frame: the
    // tracker fails that request alone with it. By default: send_frame(), never refused.
    virtual std::error_code send_request(Bytes frame, std::uintptr_t tag, bool last) {
        (void)tag;
        (void)last;
        send_frame(frame);
        return {};
    }
    // A transmission of request `tag` got no answer within its timeout (called from
    // on_timer() before the request is retried or failed; not for a refused frame).
    virtual void unanswered(std::uintptr_t tag) { (void)tag; }

  protected:
    ~FrameSink() = default;
};

// The owner's check of an answer (see the contract above): true when `response`, which
// has the SID and command code of the request tagged `tag` sent with header `request`,
// is that request's answer. Must not call back into the tracker.
class AnswerCheck {
  public:
    virtual bool answers(std::uintptr_t tag, const Header& request, const Header& response) = 0;

  protected:
    ~AnswerCheck() = default;
};

class RequestTracker {
  public:
    // Called once per submitted request: the decoded response (views valid only during
    // the call; the end code is not interpreted) or the failure.
    using Completion = std::function<void(Result<ResponseView>)>;

    enum class Disposition { matched, stale, invalid };

    // `capacity`: the most requests accepted at once (at most max_in_flight; finsd's
    // instructions: 32), the room reserved for their slots.
    explicit RequestTracker(FrameSink& sink, std::uint8_t gateway_count = default_gateway_count,
                            std::size_t capacity = max_in_flight);
    RequestTracker(const RequestTracker&) = delete;
    RequestTracker& operator=(const RequestTracker&) = delete;

    // Sets the header addresses, makes every SID clean and sends every held request.
    void link_up(const NodeAddress& destination, const NodeAddress& source, SteadyTime now);
    // Fails every request (sent or held) with `reason`; later submits are held.
    void link_down(std::error_code reason);
    [[nodiscard]] bool is_link_up() const noexcept { return link_up_; }

    // Builds the frame and sends it (or holds or queues it, see above). Fails with
    // too_many_in_flight, request_too_long or invalid_argument (retries > 15); `done` is
    // then left untouched (not moved from) and never called.
    Result<void> submit(CommandCode command, Bytes parameters, const RequestTiming& timing,
                        Completion&& done, SteadyTime now, const RequestOptions& options = {});
    // ICF bit 0 set: sends and forgets (no SID is reserved: nothing answers). Fails with
    // not_connected while the link is down, or with the sink's error when it refuses the
    // frame. Returns the SID put in the frame.
    Result<std::uint8_t> submit_no_response(CommandCode command, Bytes parameters,
                                            const RequestOptions& options = {});

    // `check`: the owner decides which answers match (see the contract above).
    Disposition on_frame(Bytes frame, SteadyTime now, AnswerCheck* check = nullptr);
    // Retransmits or fails every request whose deadline is <= now, and sends queued
    // requests whose SID has left quarantine.
    void on_timer(SteadyTime now);
    // The earliest request deadline, or end of a quarantine a queued request waits for.
    [[nodiscard]] std::optional<SteadyTime> next_deadline() const noexcept;

    // Fails every request with `reason`; the link state is unchanged.
    void cancel_all(std::error_code reason, SteadyTime now);
    // Fails only the requests sent and not answered (e.g. the one on a Host Link line that
    // got an error answer); held and queued requests stay.
    void fail_sent(std::error_code reason, SteadyTime now);
    // At most `window` requests sent and unanswered at once; the others wait in the queue
    // with their clock stopped (Host Link is half duplex: 1). Default: no limit (256).
    void set_window(std::size_t window) noexcept { window_ = window == 0 ? 1 : window; }
    // Largest frame a request may have (Host Link: 552 bytes); submit() refuses longer ones
    // with request_too_long.
    void set_max_frame(std::size_t size) noexcept { max_frame_ = std::min(size, max_frame_size); }

    // Requests accepted and not ended yet (sent, queued for a SID, or held).
    [[nodiscard]] std::size_t in_flight() const noexcept { return in_flight_; }
    // Requests held for the link or queued for a SID.
    [[nodiscard]] std::size_t waiting() const noexcept { return queue_.size(); }
    [[nodiscard]] const TrackerStats& stats() const noexcept { return stats_; }
    [[nodiscard]] const NodeAddress& destination() const noexcept { return destination_; }
    // The node that last answered a request addressed to another node, since the last
    // answer that matched (see the contract above).
    [[nodiscard]] const std::optional<NodeAddress>& other_node() const noexcept {
        return other_node_;
    }
    [[nodiscard]] const NodeAddress& source() const noexcept { return source_; }
    void set_gateway_count(std::uint8_t count) noexcept { gateway_count_ = count; }
    // An answer must come from exactly the destination's node, 00 included
    // (ClientOptions::destination_as_given); off: a 00 sent may come back as the real value.
    void set_exact_destination(bool exact) noexcept { exact_destination_ = exact; }
    void set_quarantine(std::chrono::nanoseconds q) noexcept { sids_.set_quarantine(q); }
    // A clean SID rests rest_rtts round trips (at least min_clean_rest) before reuse.
    static constexpr int rest_rtts = 4;
    static constexpr std::chrono::microseconds min_clean_rest{500};
    // Off: a clean SID is reused as soon as the least-recently-used order reaches it, with
    // no rest (finsd's instructions: at most 32 in flight, so 224 other SIDs come first;
    // a rest of 4 round trips made them wait for SIDs at 32 in flight). Takes effect at
    // the next link_up().
    void set_rest_clean_ids(bool rest) noexcept { rest_clean_ = rest; }
    [[nodiscard]] const SidPool& service_ids() const noexcept { return sids_; }

  private:
    static constexpr std::uint16_t none = 0xFFFF;

    struct Request {
        bool busy = false;
        std::uint16_t sid = none;  // none while held or queued
        CommandCode command;
        Header header;
        unsigned attempts_left = 0;
        unsigned transmissions = 0;
        std::chrono::milliseconds timeout{};
        SteadyTime deadline{};
        SteadyTime sent_at{};  // first transmission
        std::size_t size = 0;
        std::uintptr_t tag = 0;
        std::optional<NodeAddress> destination;  // own addresses (RequestOptions)
        std::optional<NodeAddress> source;
        std::chrono::nanoseconds quarantine{0};
        std::error_code refused;  // the sink refused its frame: fails at the next on_timer()
        std::array<std::uint8_t, max_frame_size> frame{};
        Completion done;
    };

    Header make_header(std::uint8_t service_id, bool response_required,
                       const RequestOptions& options) const noexcept;
    // Hands the frame to the sink; a refusal marks the request (deadline `now`).
    void transmit(Request& request, SteadyTime now);
    // Gives queued requests a SID, oldest first, and sends them; stops at the first that
    // finds none.
    void pump(SteadyTime now);
    // Frees a request (and its SID) and hands back its completion.
    Completion finish(std::uint16_t index, bool answered, SteadyTime now);
    bool addresses_match(const Header& request, const Header& response) const noexcept;
    void fail_all(std::error_code reason, SteadyTime now);

    FrameSink& sink_;
    std::vector<Request> requests_;             // up to max_in_flight, made on demand
    std::vector<std::uint16_t> free_requests_;  // indexes into requests_
    std::array<std::uint16_t, 256> by_sid_{};   // request index of each SID in flight
    std::deque<std::uint16_t> queue_;           // held or waiting for a SID, oldest first
    SidPool sids_;
    std::uint8_t next_unanswered_sid_ = 0;
    std::chrono::nanoseconds smoothed_rtt_{0};  // of answers to first attempts
    std::size_t in_flight_ = 0;
    std::size_t capacity_;
    std::size_t window_ = max_in_flight;
    std::size_t max_frame_ = max_frame_size;
    bool link_up_ = false;
    std::uint8_t gateway_count_;
    NodeAddress destination_;
    NodeAddress source_;
    TrackerStats stats_;
    std::optional<NodeAddress> other_node_;
    bool exact_destination_ = false;
    bool rest_clean_ = true;
};

}  // namespace fins
