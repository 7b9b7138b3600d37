#include "client/request_tracker.hpp"

#include <algorithm>
#include <utility>

namespace fins {

RequestTracker::RequestTracker(FrameSink& sink, std::uint8_t gateway_count)
    : sink_(sink), slots_(max_in_flight), gateway_count_(gateway_count) {}

std::optional<std::uint8_t> RequestTracker::allocate_service_id() noexcept {
    for (std::size_t i = 0; i < max_in_flight; ++i) {
        auto id = static_cast<std::uint8_t>(next_service_id_ + i);
        if (!slots_[id].busy) {
            next_service_id_ = static_cast<std::uint8_t>(id + 1);
            return id;
        }
    }
    return std::nullopt;
}

Header RequestTracker::make_header(std::uint8_t service_id, bool response_required) const noexcept {
    Header h;
    h.icf =
        response_required ? icf_gateway : static_cast<std::uint8_t>(icf_gateway | icf_no_response);
    h.gateway_count = gateway_count_;
    h.destination = destination_;
    h.source = source_;
    h.service_id = service_id;
    return h;
}

void RequestTracker::transmit(Slot& slot) {
    sink_.send_frame(Bytes{slot.frame.data(), slot.size});
}

Result<std::uint8_t> RequestTracker::submit(CommandCode command, Bytes parameters,
                                            const RequestTiming& timing, Completion&& done,
                                            SteadyTime now) {
    if (timing.retries > max_retries)
        return Unexpected(make_error_code(ClientError::invalid_argument));
    if (header_size + command_code_size + parameters.size() > max_frame_size)
        return Unexpected(make_error_code(ClientError::request_too_long));
    auto id = allocate_service_id();
    if (!id) return Unexpected(make_error_code(ClientError::too_many_in_flight));

    Slot& slot = slots_[*id];
    slot.header = make_header(*id, true);
    auto size = encode_request(slot.header, command, parameters, slot.frame);
    if (!size) return Unexpected(size.error());
    slot.busy = true;
    slot.sent = false;
    slot.command = command;
    slot.size = *size;
    slot.attempts_left = timing.retries;
    slot.timeout = timing.timeout.count() > 0 ? timing.timeout : default_timeout;
    slot.deadline = now + slot.timeout;
    slot.done = std::move(done);
    ++in_flight_;
    if (link_up_) {
        slot.sent = true;
        ++stats_.sent;
        transmit(slot);
    }
    return *id;
}

Result<std::uint8_t> RequestTracker::submit_no_response(CommandCode command, Bytes parameters) {
    if (!link_up_) return Unexpected(make_error_code(ClientError::not_connected));
    auto id = allocate_service_id();
    if (!id) return Unexpected(make_error_code(ClientError::too_many_in_flight));
    std::array<std::uint8_t, max_frame_size> frame{};
    auto size = encode_request(make_header(*id, false), command, parameters, frame);
    if (!size) return Unexpected(size.error());
    ++stats_.sent;
    sink_.send_frame(Bytes{frame.data(), *size});
    return *id;
}

void RequestTracker::link_up(const NodeAddress& destination, const NodeAddress& source,
                             SteadyTime now) {
    (void)now;  // held requests keep the deadline they got at submit()
    destination_ = destination;
    source_ = source;
    link_up_ = true;
    for (auto& slot : slots_) {
        if (!slot.busy || slot.sent) continue;
        slot.header.destination = destination_;
        slot.header.source = source_;
        ByteWriter w(MutableBytes{slot.frame.data(), header_size});
        write_header(w, slot.header);
        slot.sent = true;
        ++stats_.sent;
        transmit(slot);
    }
}

void RequestTracker::link_down(std::error_code reason) {
    link_up_ = false;
    fail_all(reason);
}

void RequestTracker::cancel_all(std::error_code reason) {
    fail_all(reason);
}

void RequestTracker::fail_all(std::error_code reason) {
    // Free every slot before calling anyone, so completions may submit again.
    std::vector<Completion> failed;
    failed.reserve(in_flight_);
    for (auto& slot : slots_) {
        if (!slot.busy) continue;
        slot.busy = false;
        failed.push_back(std::move(slot.done));
        slot.done = nullptr;
    }
    in_flight_ = 0;
    stats_.failed += failed.size();
    for (auto& done : failed)
        if (done) done(Unexpected(reason));
}

bool RequestTracker::addresses_match(const Header& request, const Header& response) const noexcept {
    // A field sent as 00 ("local network", "local node") may come back as the real value.
    auto same = [](std::uint8_t sent, std::uint8_t got) { return sent == 0 || sent == got; };
    const auto& to = request.destination;
    const auto& from = request.source;
    return same(to.network, response.source.network) && same(to.node, response.source.node) &&
           to.unit == response.source.unit && same(from.network, response.destination.network) &&
           same(from.node, response.destination.node) && from.unit == response.destination.unit;
}

RequestTracker::Disposition RequestTracker::on_frame(Bytes frame, SteadyTime now) {
    (void)now;
    auto response = decode_response(frame);
    if (!response) {
        ++stats_.invalid_discarded;
        return Disposition::invalid;
    }
    Slot& slot = slots_[response->header.service_id];
    if (!slot.busy || !slot.sent || response->command != slot.command) {
        ++stats_.stale_discarded;
        return Disposition::stale;
    }
    if (!addresses_match(slot.header, response->header)) {
        ++stats_.invalid_discarded;
        return Disposition::invalid;
    }
    auto done = std::move(slot.done);
    slot.done = nullptr;
    slot.busy = false;
    --in_flight_;
    ++stats_.completed;
    if (done) done(*response);
    return Disposition::matched;
}

void RequestTracker::on_timer(SteadyTime now) {
    std::vector<Completion> expired;
    for (auto& slot : slots_) {
        if (!slot.busy || slot.deadline > now) continue;
        if (slot.attempts_left > 0) {
            --slot.attempts_left;
            slot.deadline = now + slot.timeout;
            if (slot.sent) {
                ++stats_.retransmitted;
                transmit(slot);
            }
            continue;
        }
        slot.busy = false;
        --in_flight_;
        ++stats_.timed_out;
        expired.push_back(std::move(slot.done));
        slot.done = nullptr;
    }
    for (auto& done : expired)
        if (done) done(Unexpected(make_error_code(ClientError::timeout)));
}

std::optional<SteadyTime> RequestTracker::next_deadline() const noexcept {
    std::optional<SteadyTime> next;
    if (in_flight_ == 0) return next;
    for (const auto& slot : slots_)
        if (slot.busy && (!next || slot.deadline < *next)) next = slot.deadline;
    return next;
}

}  // namespace fins
