#include "engine/request_tracker.hpp"

#include <algorithm>
#include <utility>

namespace fins {

RequestTracker::RequestTracker(FrameSink& sink, std::uint8_t gateway_count, std::size_t capacity)
    : sink_(sink),
      sids_(default_timeout * default_quarantine_timeouts),
      capacity_(std::clamp<std::size_t>(capacity, 1, max_in_flight)),
      gateway_count_(gateway_count) {
    by_sid_.fill(none);
    // Room for `capacity` slots (about 2 KB each, the frame buffer), made as they are
    // first needed: a client that keeps a few requests in flight (fins-bridge's thousand,
    // `window` each) touches a few slots, not 540 KB. Reserved, so a slot never moves.
    requests_.reserve(capacity_);
    free_requests_.reserve(capacity_);
}

Header RequestTracker::make_header(std::uint8_t service_id, bool response_required,
                                   const RequestOptions& options) const noexcept {
    Header h;
    h.icf =
        response_required ? icf_gateway : static_cast<std::uint8_t>(icf_gateway | icf_no_response);
    h.gateway_count = gateway_count_;
    h.destination = options.destination.value_or(destination_);
    h.source = options.source.value_or(source_);
    h.service_id = service_id;
    return h;
}

void RequestTracker::transmit(Request& request, SteadyTime now) {
    ++request.transmissions;
    auto refused = sink_.send_request(Bytes{request.frame.data(), request.size}, request.tag,
                                      request.attempts_left == 0);
    if (!refused) return;
    // Nothing went out, so nothing can answer it: no unanswered transmission to quarantine
    // its SID for, and no retry (on_timer() fails it at once).
    --request.transmissions;
    request.refused = refused;
    request.attempts_left = 0;
    request.deadline = now;
}

Result<void> RequestTracker::submit(CommandCode command, Bytes parameters,
                                    const RequestTiming& timing, Completion&& done, SteadyTime now,
                                    const RequestOptions& options) {
    if (timing.retries > max_retries)
        return Unexpected(make_error_code(ClientError::invalid_argument));
    if (header_size + command_code_size + parameters.size() > max_frame_)
        return Unexpected(make_error_code(ClientError::request_too_long));
    if (free_requests_.empty()) {
        if (requests_.size() >= capacity_)
            return Unexpected(make_error_code(ClientError::too_many_in_flight));
        requests_.emplace_back();
        free_requests_.push_back(static_cast<std::uint16_t>(requests_.size() - 1));
    }
    const auto index = free_requests_.back();
    Request& r = requests_[index];
    r.header = make_header(0, true, options);
    auto size = encode_request(r.header, command, parameters, r.frame);
    if (!size) return Unexpected(size.error());
    free_requests_.pop_back();
    r.busy = true;
    r.sid = none;
    r.command = command;
    r.size = *size;
    r.attempts_left = timing.retries;
    r.transmissions = 0;
    r.timeout = timing.timeout.count() > 0 ? timing.timeout : default_timeout;
    r.deadline = now + r.timeout;
    r.tag = options.tag;
    r.destination = options.destination;
    r.source = options.source;
    r.quarantine = options.quarantine;
    r.refused = {};
    r.done = std::move(done);
    ++in_flight_;
    queue_.push_back(index);
    pump(now);
    if (link_up_ && r.sid == none) ++stats_.waited_for_id;
    return {};
}

void RequestTracker::pump(SteadyTime now) {
    while (link_up_ && !queue_.empty() && in_flight_ - queue_.size() < window_) {
        auto sid = sids_.acquire(now);
        if (!sid) return;
        const auto index = queue_.front();
        queue_.pop_front();
        Request& r = requests_[index];
        r.sid = *sid;
        by_sid_[*sid] = index;
        r.header.service_id = *sid;
        r.header.destination = r.destination.value_or(destination_);
        r.header.source = r.source.value_or(source_);
        ByteWriter w(MutableBytes{r.frame.data(), header_size});
        write_header(w, r.header);
        r.deadline = now + r.timeout;  // each attempt that is sent gets a whole timeout
        r.sent_at = now;
        ++stats_.sent;
        transmit(r, now);
    }
}

Result<std::uint8_t> RequestTracker::submit_no_response(CommandCode command, Bytes parameters,
                                                        const RequestOptions& options) {
    if (!link_up_) return Unexpected(make_error_code(ClientError::not_connected));
    // Nothing answers such a frame, so its SID needs no reservation; a counter of its own
    // keeps consecutive frames distinguishable in a capture. It avoids SIDs in flight, so
    // that even a unit that answers anyway cannot complete another request.
    auto id = next_unanswered_sid_++;
    for (std::size_t i = 0; i < by_sid_.size() && by_sid_[id] != none; ++i)
        id = next_unanswered_sid_++;
    std::array<std::uint8_t, max_frame_size> frame{};
    auto size = encode_request(make_header(id, false, options), command, parameters, frame);
    if (!size) return Unexpected(size.error());
    if (auto refused = sink_.send_request(Bytes{frame.data(), *size}, options.tag, true)) {
        ++stats_.refused;
        return Unexpected(refused);
    }
    ++stats_.sent;
    return id;
}

void RequestTracker::link_up(const NodeAddress& destination, const NodeAddress& source,
                             SteadyTime now) {
    destination_ = destination;
    source_ = source;
    link_up_ = true;
    sids_.reset();
    smoothed_rtt_ = {};
    sids_.set_min_rest(rest_clean_ ? min_clean_rest : std::chrono::microseconds{0});
    pump(now);
}

void RequestTracker::link_down(std::error_code reason) {
    link_up_ = false;
    // Time is irrelevant here: the SIDs are reset by the next link_up().
    fail_all(reason, SteadyTime{});
}

void RequestTracker::cancel_all(std::error_code reason, SteadyTime now) {
    fail_all(reason, now);
}

void RequestTracker::fail_sent(std::error_code reason, SteadyTime now) {
    std::vector<Completion> failed;
    for (std::size_t i = 0; i < requests_.size(); ++i)
        if (requests_[i].busy && requests_[i].sid != none)
            failed.push_back(finish(static_cast<std::uint16_t>(i), false, now));
    stats_.failed += failed.size();
    pump(now);
    for (auto& done : failed)
        if (done) done(Unexpected(reason));
}

RequestTracker::Completion RequestTracker::finish(std::uint16_t index, bool answered,
                                                  SteadyTime now) {
    Request& r = requests_[index];
    if (r.sid != none) {
        by_sid_[r.sid] = none;
        const auto before = sids_.quarantined_count();
        const auto unanswered = r.transmissions - (answered && r.transmissions > 0 ? 1U : 0U);
        if (r.quarantine.count() > 0 && unanswered > 0) {
            // This request's own quarantine (RequestOptions), for this release only.
            const auto usual = sids_.quarantine();
            sids_.set_quarantine(r.quarantine);
            sids_.release(static_cast<std::uint8_t>(r.sid), unanswered, now);
            sids_.set_quarantine(usual);
        } else {
            sids_.release(static_cast<std::uint8_t>(r.sid), unanswered, now);
        }
        stats_.quarantined += sids_.quarantined_count() - before;
        r.sid = none;
    } else {
        auto it = std::find(queue_.begin(), queue_.end(), index);
        if (it != queue_.end()) queue_.erase(it);
    }
    r.busy = false;
    --in_flight_;
    free_requests_.push_back(index);
    auto done = std::move(r.done);
    r.done = nullptr;
    return done;
}

void RequestTracker::fail_all(std::error_code reason, SteadyTime now) {
    // Free every request before calling anyone, so completions may submit again.
    queue_.clear();
    std::vector<Completion> failed;
    failed.reserve(in_flight_);
    for (std::size_t i = 0; i < requests_.size(); ++i)
        if (requests_[i].busy) failed.push_back(finish(static_cast<std::uint16_t>(i), false, now));
    stats_.failed += failed.size();
    pump(now);
    for (auto& done : failed)
        if (done) done(Unexpected(reason));
}

bool RequestTracker::addresses_match(const Header& request, const Header& response) const noexcept {
    // A field sent as 00 ("local network", "local node") may come back as the real value.
    auto same = [](std::uint8_t sent, std::uint8_t got) { return sent == 0 || sent == got; };
    // Unless the destination was given as is: then it answers as the node it was sent to.
    const bool node = exact_destination_ ? request.destination.node == response.source.node
                                         : same(request.destination.node, response.source.node);
    const auto& to = request.destination;
    const auto& from = request.source;
    return same(to.network, response.source.network) && node && to.unit == response.source.unit &&
           same(from.network, response.destination.network) &&
           same(from.node, response.destination.node) && from.unit == response.destination.unit;
}

RequestTracker::Disposition RequestTracker::on_frame(Bytes frame, SteadyTime now,
                                                     AnswerCheck* check) {
    auto response = decode_response(frame);
    if (!response) {
        ++stats_.invalid_discarded;
        return Disposition::invalid;
    }
    const auto sid = response->header.service_id;
    const auto index = by_sid_[sid];
    if (index == none || response->command != requests_[index].command) {
        ++stats_.stale_discarded;
        const auto before = sids_.quarantined_count();
        const auto raised_before = sids_.raised_count();
        sids_.unexpected_answer(sid, index != none, now);
        stats_.quarantined += sids_.quarantined_count() - before;
        stats_.quarantine_raised += sids_.raised_count() - raised_before;
        return Disposition::stale;
    }
    if (check) {
        if (!check->answers(requests_[index].tag, requests_[index].header, response->header)) {
            ++stats_.invalid_discarded;
            return Disposition::invalid;
        }
    } else if (!addresses_match(requests_[index].header, response->header)) {
        ++stats_.invalid_discarded;
        auto only_node = response->header;
        only_node.source.node = requests_[index].header.destination.node;
        if (addresses_match(requests_[index].header, only_node)) {
            ++stats_.other_node_answers;
            other_node_ = response->header.source;
        }
        return Disposition::invalid;
    }
    other_node_.reset();
    if (rest_clean_ && requests_[index].transmissions == 1) {
        // Smoothed like TCP's SRTT (RFC 6298, gain 1/8); sets how long clean SIDs rest.
        const auto rtt = now - requests_[index].sent_at;
        smoothed_rtt_ =
            smoothed_rtt_.count() == 0 ? rtt : smoothed_rtt_ + (rtt - smoothed_rtt_) / 8;
        const auto rest = std::clamp<std::chrono::nanoseconds>(smoothed_rtt_ * rest_rtts,
                                                               min_clean_rest, sids_.quarantine());
        sids_.set_min_rest(rest);
    }
    auto done = finish(index, true, now);
    ++stats_.completed;
    pump(now);
    if (done) done(*response);
    return Disposition::matched;
}

void RequestTracker::on_timer(SteadyTime now) {
    std::vector<std::pair<Completion, std::error_code>> expired;
    for (std::size_t i = 0; i < requests_.size(); ++i) {
        Request& r = requests_[i];
        if (!r.busy || r.deadline > now) continue;
        if (r.sid == none && link_up_) continue;  // waits for a SID: its clock has not started
        if (!r.refused) {
            if (r.sid != none) sink_.unanswered(r.tag);
            if (r.attempts_left > 0) {
                --r.attempts_left;
                r.deadline = now + r.timeout;
                if (r.sid == none) continue;
                ++stats_.retransmitted;
                transmit(r, now);
                if (!r.refused) continue;
            }
        }
        const auto reason = r.refused ? r.refused : make_error_code(ClientError::timeout);
        ++(r.refused ? stats_.refused : stats_.timed_out);
        expired.emplace_back(finish(static_cast<std::uint16_t>(i), false, now), reason);
    }
    pump(now);
    for (auto& [done, reason] : expired)
        if (done) done(Unexpected(reason));
}

std::optional<SteadyTime> RequestTracker::next_deadline() const noexcept {
    std::optional<SteadyTime> next;
    if (in_flight_ == 0) return next;
    for (const auto& r : requests_) {
        if (!r.busy || (r.sid == none && link_up_)) continue;
        if (!next || r.deadline < *next) next = r.deadline;
    }
    // A full window is reopened by an answer or a deadline above, not by a SID.
    if (link_up_ && !queue_.empty() && in_flight_ - queue_.size() < window_) {
        auto usable = sids_.next_usable();
        if (usable && (!next || *usable < *next)) next = usable;
    }
    return next;
}

}  // namespace fins
