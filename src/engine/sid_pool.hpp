// Service IDs (SID, frames 1.1) of the client: which one a new request may use.
//
// A FINS answer is matched to its request by SID alone (plus command code and node
// addresses, which are the same for every read): a read answer carries no address. So a
// SID must not be handed to a new request while an answer to its previous use can still
// arrive, or that answer completes the new request with another address's data.
//
// Rules (no clock of its own: the caller passes `now`):
// - A SID released with answers outstanding (its request was retransmitted, timed out, or
//   failed after it was sent) is *suspect*: it is quarantined for `quarantine` after its
//   release. Late answers to it are dropped as stale meanwhile.
// - A SID released with every transmission answered is *clean* and goes to the back of a
//   least-recently-used queue, so (256 - in flight) other SIDs are used before it again,
//   and it rests at least `min_rest` (the caller sets it from the round-trip time) so a
//   duplicate answer right behind the first is seen as stale, not as the next answer.
// - Evidence that the network duplicates or invents answers (an answer for a free SID
//   whose transmissions were all answered, or for a busy SID with another command code)
//   puts the pool in *troubled* mode for `trouble_quarantines` quarantines: every SID
//   released within `quarantine` before such evidence or while troubled, clean ones
//   included, is quarantined too, because a duplicate of its answer may still be on the
//   way.
// - The quarantine follows the network: an awaited late answer (to a SID in quarantine
//   for it) that comes in the second half of the configured quarantine, L after its SID's
//   release, shows that datagrams live almost that long, so the quarantine grows to 2L
//   (at most `max_stretch` times the configured one) for every SID released from then
//   on and every SID in quarantine now. Queueing delay grows gradually, so the answers
//   that come before the end show how late the next ones may be; and a longer quarantine
//   leaves fewer SIDs usable, which lowers the load that made the answers late. After
//   `trouble_quarantines` of the grown quarantine without such an answer, the configured
//   one applies again.
// - acquire() prefers clean SIDs (least recently used first), then the suspect SID whose
//   quarantine ended first. A SID in quarantine is never handed out early: when none is
//   usable, acquire() returns nothing and next_usable() says when to try again.
// - reset() (a fresh connection or socket: no old answer can reach it) makes all 256
//   clean, in order 00, 01, ... FF.
// The assumption behind it: no datagram outlives the quarantine in the network, and one
// that would gives notice by the answers before it.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>

namespace fins {

using SteadyTime = std::chrono::steady_clock::time_point;

class SidPool {
  public:
    static constexpr std::size_t size = 256;
    // A network seen duplicating is assumed to go on doing so for this many quarantines.
    static constexpr int trouble_quarantines = 4;
    // The quarantine grows to at most this many times the configured one.
    static constexpr int max_stretch = 64;

    explicit SidPool(std::chrono::nanoseconds quarantine);

    void reset();
    void set_quarantine(std::chrono::nanoseconds quarantine) noexcept { quarantine_ = quarantine; }
    void set_min_rest(std::chrono::nanoseconds rest) noexcept { min_rest_ = rest; }
    [[nodiscard]] std::chrono::nanoseconds min_rest() const noexcept { return min_rest_; }
    [[nodiscard]] std::chrono::nanoseconds quarantine() const noexcept { return quarantine_; }
    // The quarantine a SID released at `now` gets: the configured one, or more while late
    // answers show that the network holds datagrams nearly that long (see above).
    [[nodiscard]] std::chrono::nanoseconds effective_quarantine(SteadyTime now) const noexcept {
        return now < stretched_until_ && stretched_ > quarantine_ ? stretched_ : quarantine_;
    }

    std::optional<std::uint8_t> acquire(SteadyTime now);
    // `unanswered`: transmissions of the request that got no answer.
    void release(std::uint8_t sid, unsigned unanswered, SteadyTime now);
    // An answer that matched no request: `busy` when the SID is in use by another request.
    void unexpected_answer(std::uint8_t sid, bool busy, SteadyTime now);

    // The earliest time a free SID becomes usable (nothing when none is free).
    [[nodiscard]] std::optional<SteadyTime> next_usable() const noexcept;
    [[nodiscard]] bool has_clean() const noexcept { return clean_.head != none; }
    [[nodiscard]] bool is_quarantined(std::uint8_t sid) const noexcept {
        return sids_[sid].where == Where::suspect;
    }
    [[nodiscard]] bool troubled(SteadyTime now) const noexcept { return now < trouble_until_; }
    // How many times a SID was put into quarantine.
    [[nodiscard]] std::uint64_t quarantined_count() const noexcept { return quarantined_count_; }
    // How many times late answers made the quarantine longer.
    [[nodiscard]] std::uint64_t raised_count() const noexcept { return raised_count_; }

  private:
    static constexpr std::uint16_t none = 0xFFFF;
    enum class Where : std::uint8_t { busy, clean, suspect };

    struct Sid {
        Where where = Where::clean;
        std::uint8_t unanswered = 0;
        SteadyTime released{};
        SteadyTime usable_at{};  // suspect: end of quarantine
        std::uint16_t prev = none;
        std::uint16_t next = none;
    };
    struct List {
        std::uint16_t head = none;
        std::uint16_t tail = none;
    };

    void unlink(List& list, std::uint16_t sid) noexcept;
    void push_back(List& list, std::uint16_t sid) noexcept;
    void insert_after(List& list, std::uint16_t after, std::uint16_t sid) noexcept;
    // Into the suspect list, kept sorted by usable_at.
    void quarantine(std::uint16_t sid, SteadyTime usable_at) noexcept;
    void trouble(SteadyTime now) noexcept;
    // An awaited answer came `late` after its SID's release.
    void late_answer(std::chrono::nanoseconds late, SteadyTime now) noexcept;

    std::chrono::nanoseconds quarantine_;
    std::chrono::nanoseconds min_rest_{0};
    std::array<Sid, size> sids_{};
    List clean_;    // least recently released first
    List suspect_;  // earliest end of quarantine first
    SteadyTime trouble_until_{};
    std::uint64_t quarantined_count_ = 0;
    std::chrono::nanoseconds stretched_{0};  // the grown quarantine, until stretched_until_
    SteadyTime stretched_until_{};
    std::uint64_t raised_count_ = 0;
};

}  // namespace fins
