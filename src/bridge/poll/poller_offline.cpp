// PlcPoller's online/offline state: going offline fails everything waiting and publishes
// the status; an offline PLC is probed again after a back-off with full jitter.
#include "bridge/poll/poller_parts.hpp"

#include <fmt/format.h>

namespace fins::bridge {

std::string PlcPoller::other_node_text(const NodeAddress& from) const {
    const NodeAddress to = destination();
    const char* why = plc_.dest                          ? "its dest"
                      : plc_.transport == Transport::tcp ? "the node the FINS/TCP handshake named"
                                                         : "the last number of its IP address";
    return fmt::format(
        "answers come from node {}, requests go to node {} ({}): set dest = \"{}.{}.{}\" for "
        "plc \"{}\"",
        from.node, to.node, why, from.network, from.node, to.unit, plc_.name);
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
    // Frames that timed out while another node answered them (the client saw it since the
    // last answer that matched): that is the error to fix.
    const auto answered_by = client_->other_node();
    const bool other_node = answered_by && why == make_error_code(ClientError::timeout);
    last_error_ = other_node ? other_node_text(*answered_by) : error_text(why);
    // Published when the PLC goes offline, and again only when another node's answers
    // start or stop being the reason: not for every probe that fails the same way.
    const bool news = state_ != State::offline || other_node != other_node_reported_;
    other_node_reported_ = other_node;
    state_ = State::offline;
    ++generation_;  // completions of this connection and pending timers return early
    // Everything waiting fails now: the cycles publish their tags with this error. The
    // requests still with the client end there (timeout, or canceled by the reconnect)
    // and their completions, of the old generation, are dropped.
    std::vector<Request> failed = std::move(in_flight_);
    in_flight_.clear();
    failed.insert(failed.end(), ready_.begin(), ready_.end());
    ready_.clear();
    for (auto& r : failed)
        complete(r, nullptr, why);
    for (auto& gs : groups_) {
        gs->in_cycle = false;
        gs->outstanding = 0;
    }
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
            // A fresh connection and handshake (the old one may still be up after
            // timeouts): its outcome puts the PLC online or backs off again.
            client_->close();
            open();
            return;
        }
        // UDP: the first frame of the first group; the client opens the socket first if
        // it is closed (a name that did not resolve is resolved again).
        if (groups_.empty() || groups_[0]->plan.frames.empty()) return;
        Request probe{Request::Kind::probe};
        probe.command = groups_[0]->commands[0];
        enqueue(probe);
    });
}

}  // namespace fins::bridge
