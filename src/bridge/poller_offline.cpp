// PlcPoller's online/offline state: going offline fails everything waiting and publishes
// the status; an offline PLC is probed again after a back-off with full jitter.
#include "bridge/poller_parts.hpp"

namespace fins::bridge {

void PlcPoller::go_online() {
    if (state_ == State::online) return;
    state_ = State::online;
    backoff_.reset();
    for (auto& gs : groups_)
        gs->need_full = true;
    events_.status_changed({&plc_, true, last_error_, now_ms()});
}

void PlcPoller::go_offline(std::error_code why) {
    if (!running_) return;
    last_error_ = error_text(why);
    const bool was = state_ == State::offline;
    state_ = State::offline;
    ++generation_;  // handlers of this connection and pending timers return early
    timeout_timer_.cancel();
    armed_.reset();
    // Everything waiting fails now: the cycles publish their tags with this error. The
    // SIDs in flight are quarantined: a late answer finds nothing.
    std::vector<Request> failed;
    window_.take_all(PollClock::now(), failed);
    failed.insert(failed.end(), ready_.begin(), ready_.end());
    ready_.clear();
    for (auto& r : failed)
        complete(r, nullptr, why);
    for (auto& gs : groups_) {
        gs->in_cycle = false;
        gs->outstanding = 0;
    }
    if (plc_.transport == Transport::tcp) close_socket();
    if (!was) events_.status_changed({&plc_, false, last_error_, now_ms()});
    // The groups' timers belonged to the old generation: keep them on their grid.
    for (std::size_t g = 0; g < groups_.size(); ++g)
        schedule(g);
    backoff();
}

void PlcPoller::backoff() {
    backoff_timer_.expires_after(backoff_.next());
    backoff_timer_.async_wait([this, gen = generation_](boost::system::error_code ec) {
        if (gen != generation_ || ec) return;
        if (plc_.transport == Transport::tcp) {
            tcp_connect();
            return;
        }
        if (!udp_.is_open()) {
            open();
            if (!udp_.is_open()) return;
        }
        if (groups_.empty() || groups_[0]->plan.frames.empty()) return;
        Request probe{Request::Kind::probe};
        probe.command = groups_[0]->commands[0];
        probe.attempts = plc_.retries;  // one try; a failure backs off again
        enqueue(probe);
    });
}

}  // namespace fins::bridge
