#include "bridge/request_window.hpp"

#include <algorithm>

namespace fins::bridge {

RequestWindow::RequestWindow(std::size_t capacity, PollClock::duration quarantine)
    : capacity_(capacity), quarantine_(quarantine) {
    in_flight_.reserve(capacity + 1);  // + the TCP handshake
}

std::uint8_t RequestWindow::allocate(PollClock::time_point now) {
    // Within the quarantine: the oldest released by an answer (a duplicate of an answer
    // comes at once, if ever), else the oldest given up.
    std::optional<std::uint8_t> answered, given_up;
    const auto older = [this](std::optional<std::uint8_t> best, std::uint8_t sid) {
        return !best || *released_[sid] < *released_[*best];
    };
    for (int i = 0; i < 256; ++i) {
        const auto sid = static_cast<std::uint8_t>(next_ + i);
        if (busy_[sid]) continue;
        const auto& at = released_[sid];
        if (!at || *at + quarantine_ <= now) {
            next_ = static_cast<std::uint8_t>(sid + 1);
            return sid;
        }
        auto& best = given_up_[sid] ? given_up : answered;
        if (older(best, sid)) best = sid;
    }
    // At most 64 of 256 are in flight (config), so some SID is free.
    const std::uint8_t sid = answered ? *answered : *given_up;
    next_ = static_cast<std::uint8_t>(sid + 1);
    return sid;
}

void RequestWindow::add(const Request& r) {
    if (r.kind != Request::Kind::handshake) busy_[r.service_id] = true;
    in_flight_.push_back(r);
}

void RequestWindow::release(const Request& r, PollClock::time_point now, bool answered) noexcept {
    if (r.kind == Request::Kind::handshake) return;
    busy_[r.service_id] = false;
    released_[r.service_id] = now;
    given_up_[r.service_id] = !answered;
}

std::optional<Request> RequestWindow::take_answer(const Header& answer, CommandCode command,
                                                  std::uint8_t plc_node,
                                                  PollClock::time_point now) {
    if (!busy_[answer.service_id] || answer.source.node != plc_node) return std::nullopt;
    auto it = std::find_if(in_flight_.begin(), in_flight_.end(), [&](const Request& r) {
        return r.kind != Request::Kind::handshake && r.service_id == answer.service_id;
    });
    if (it == in_flight_.end() || it->command != command) return std::nullopt;
    Request r = *it;
    *it = in_flight_.back();
    in_flight_.pop_back();
    release(r, now, true);
    return r;
}

bool RequestWindow::from_other_node(const Header& answer, CommandCode command,
                                    std::uint8_t plc_node) const noexcept {
    if (!busy_[answer.service_id] || answer.source.node == plc_node) return false;
    return std::any_of(in_flight_.begin(), in_flight_.end(), [&](const Request& r) {
        return r.kind != Request::Kind::handshake && r.service_id == answer.service_id &&
               r.command == command;
    });
}

void RequestWindow::take_expired(PollClock::time_point now, std::vector<Request>& out) {
    for (std::size_t i = 0; i < in_flight_.size();) {
        if (in_flight_[i].deadline <= now) {
            release(in_flight_[i], now, false);
            out.push_back(in_flight_[i]);
            in_flight_[i] = in_flight_.back();
            in_flight_.pop_back();
        } else {
            ++i;
        }
    }
}

void RequestWindow::take_all(PollClock::time_point now, std::vector<Request>& out) {
    for (const auto& r : in_flight_) {
        release(r, now, false);
        out.push_back(r);
    }
    in_flight_.clear();
}

void RequestWindow::remove_handshake() noexcept {
    std::erase_if(in_flight_, [](const Request& q) { return q.kind == Request::Kind::handshake; });
}

std::optional<PollClock::time_point> RequestWindow::earliest_deadline() const noexcept {
    if (in_flight_.empty()) return std::nullopt;
    auto earliest = in_flight_.front().deadline;
    for (const auto& r : in_flight_)
        earliest = std::min(earliest, r.deadline);
    return earliest;
}

}  // namespace fins::bridge
