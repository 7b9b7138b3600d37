// PlcPoller's online/offline state: going offline fails everything waiting and publishes
// the status; an offline PLC is probed again after a back-off with full jitter.
#include "bridge/poller_parts.hpp"

#include <fmt/format.h>

namespace fins::bridge {

std::string PlcPoller::other_node_text() const {
    const NodeAddress& from = *answered_by_;
    const char* why = plc_.dest                          ? "its dest"
                      : plc_.transport == Transport::tcp ? "the node the FINS/TCP handshake named"
                                                         : "the last number of its IP address";
    return fmt::format(
        "answers come from node {}, requests go to node {} ({}): set dest = \"{}.{}.{}\" for "
        "plc \"{}\"",
        from.node, destination_.node, why, from.network, from.node, destination_.unit, plc_.name);
}

void PlcPoller::go_online() {
    if (state_ == State::online) return;
    state_ = State::online;
    other_node_reported_ = false;
    backoff_.reset();
    for (auto& gs : groups_)
        gs->need_full = true;
    events_.status_changed({&plc_, true, last_error_, now_ms()});
}

void PlcPoller::go_offline(std::error_code why) {
    if (!running_) return;
    // Frames that timed out while another node answered them: that is the error to fix.
    const bool other_node = answered_by_ && why == make_error_code(ClientError::timeout);
    last_error_ = other_node ? other_node_text() : error_text(why);
    answered_by_.reset();  // the next probe's answers tell again
    // Published when the PLC goes offline, and again only when another node's answers
    // start or stop being the reason: not for every probe that fails the same way.
    const bool news = state_ != State::offline || other_node != other_node_reported_;
    other_node_reported_ = other_node;
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
    if (news) events_.status_changed({&plc_, false, last_error_, now_ms()});
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
