#include "engine/sid_pool.hpp"

#include <algorithm>

namespace fins {

SidPool::SidPool(std::chrono::nanoseconds quarantine) : quarantine_(quarantine) {
    reset();
}

void SidPool::reset() {
    clean_ = {};
    suspect_ = {};
    trouble_until_ = {};
    stretched_ = {};
    stretched_until_ = {};
    for (std::uint16_t id = 0; id < size; ++id) {
        sids_[id] = Sid{};
        push_back(clean_, id);
    }
}

void SidPool::unlink(List& list, std::uint16_t sid) noexcept {
    auto& s = sids_[sid];
    if (s.prev != none)
        sids_[s.prev].next = s.next;
    else
        list.head = s.next;
    if (s.next != none)
        sids_[s.next].prev = s.prev;
    else
        list.tail = s.prev;
    s.prev = s.next = none;
}

void SidPool::push_back(List& list, std::uint16_t sid) noexcept {
    insert_after(list, list.tail, sid);
}

void SidPool::insert_after(List& list, std::uint16_t after, std::uint16_t sid) noexcept {
    auto& s = sids_[sid];
    s.prev = after;
    s.next = after == none ? list.head : sids_[after].next;
    if (s.prev != none)
        sids_[s.prev].next = sid;
    else
        list.head = sid;
    if (s.next != none)
        sids_[s.next].prev = sid;
    else
        list.tail = sid;
}

void SidPool::quarantine(std::uint16_t sid, SteadyTime usable_at) noexcept {
    auto& s = sids_[sid];
    if (s.where == Where::clean) unlink(clean_, sid);
    if (s.where == Where::suspect) unlink(suspect_, sid);
    s.where = Where::suspect;
    s.usable_at = usable_at;
    ++quarantined_count_;
    // Usually the latest end of quarantine: walk from the back.
    auto after = suspect_.tail;
    while (after != none && sids_[after].usable_at > usable_at)
        after = sids_[after].prev;
    insert_after(suspect_, after, sid);
}

std::optional<std::uint8_t> SidPool::acquire(SteadyTime now) {
    std::uint16_t id = none;
    if (clean_.head != none && sids_[clean_.head].released + min_rest_ <= now) {
        id = clean_.head;
        unlink(clean_, id);
    } else if (suspect_.head != none && sids_[suspect_.head].usable_at <= now) {
        id = suspect_.head;
        unlink(suspect_, id);
    } else {
        return std::nullopt;
    }
    auto& s = sids_[id];
    s.where = Where::busy;
    s.unanswered = 0;
    return static_cast<std::uint8_t>(id);
}

void SidPool::release(std::uint8_t sid, unsigned unanswered, SteadyTime now) {
    auto& s = sids_[sid];
    if (s.where != Where::busy) return;
    s.released = now;
    s.unanswered = static_cast<std::uint8_t>(unanswered > 0xFF ? 0xFF : unanswered);
    if (unanswered > 0 || troubled(now)) {
        quarantine(sid, now + effective_quarantine(now));
        return;
    }
    s.where = Where::clean;
    push_back(clean_, sid);
}

void SidPool::trouble(SteadyTime now) noexcept {
    const auto q = effective_quarantine(now);
    trouble_until_ = now + q * trouble_quarantines;
    // Clean SIDs released within the quarantine before the evidence may get a duplicate
    // too. The clean list is in release order, so they are a tail of it.
    while (clean_.tail != none && sids_[clean_.tail].released + q > now) {
        const auto id = clean_.tail;
        quarantine(id, sids_[id].released + q);
    }
}

void SidPool::late_answer(std::chrono::nanoseconds late, SteadyTime now) noexcept {
    if (late * 2 <= quarantine_) return;  // in the first half: as the quarantine expects
    const auto grown = std::min(late * 2, quarantine_ * max_stretch);
    const auto current = effective_quarantine(now);
    stretched_ = std::max(grown, current);
    stretched_until_ = now + stretched_ * trouble_quarantines;
    if (grown <= current) return;
    ++raised_count_;
    // Every SID in quarantine now rests the grown quarantine from its release too; the
    // list is sorted again by the new ends (at most 256 entries, a rare event).
    std::array<std::uint16_t, size> ids{};
    std::size_t n = 0;
    for (auto id = suspect_.head; id != none; id = sids_[id].next) {
        auto& s = sids_[id];
        s.usable_at = std::max(s.usable_at, s.released + grown);
        ids[n++] = id;
    }
    std::stable_sort(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(n),
                     [this](std::uint16_t a, std::uint16_t b) {
                         return sids_[a].usable_at < sids_[b].usable_at;
                     });
    suspect_ = {};
    for (std::size_t i = 0; i < n; ++i) {
        sids_[ids[i]].prev = sids_[ids[i]].next = none;
        push_back(suspect_, ids[i]);
    }
}

void SidPool::unexpected_answer(std::uint8_t sid, bool busy, SteadyTime now) {
    auto& s = sids_[sid];
    if (!busy && s.where != Where::busy && s.unanswered > 0) {
        --s.unanswered;  // the late answer its quarantine waits for
        late_answer(now - s.released, now);
        return;
    }
    trouble(now);
    if (!busy && s.where != Where::busy) quarantine(sid, now + quarantine_);
}

std::optional<SteadyTime> SidPool::next_usable() const noexcept {
    std::optional<SteadyTime> next;
    if (clean_.head != none) next = sids_[clean_.head].released + min_rest_;
    if (suspect_.head != none && (!next || sids_[suspect_.head].usable_at < *next))
        next = sids_[suspect_.head].usable_at;
    return next;
}

}  // namespace fins
