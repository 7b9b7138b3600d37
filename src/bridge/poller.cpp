// PlcPoller: lifecycle, the groups' tick grids, the in-flight window (send, timeouts,
// answers) and the end of a cycle. Sockets are in poller_io.cpp, writes in
// poller_write.cpp, online/offline and back-off in poller_offline.cpp; the pure parts in
// poll_schedule, request_window and tag_decode.
#include <algorithm>

#include "bridge/poller_parts.hpp"
#include "bridge/tag_decode.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/tcp.hpp"

namespace fins::bridge {

namespace {

// A SID is not reused for this long after its frame was answered or given up: longer
// than any answer arrives late in practice, shorter than 256 frames take at the rates
// the bridge polls.
PollClock::duration quarantine_of(const Plc& plc) {
    return 2 * std::chrono::duration_cast<PollClock::duration>(plc.timeout);
}

}  // namespace

PlcPoller::PlcPoller(asio::io_context& io, const Plc& plc, double phase, PollerEvents& events,
                     std::uint64_t seed)
    : io_(io),
      plc_(plc),
      phase_(phase),
      events_(events),
      udp_(io),
      tcp_(io),
      window_(plc.window, quarantine_of(plc)),
      timeout_timer_(io),
      backoff_timer_(io),
      backoff_(plc.backoff_min, plc.backoff_max, seed) {
    for (const auto& g : plc.groups) {
        auto gs = std::make_unique<GroupState>(io, g);
        gs->plan = plan_group(g.tags, g.gap_words);
        for (const auto& f : gs->plan.frames) {
            std::vector<std::uint8_t> p(max_parameter_size);
            ByteWriter w(p);
            std::vector<std::uint16_t> offsets;
            std::size_t answer = 0;
            if (f.kind == PlannedFrame::Kind::read) {
                MemoryAreaRead{f.start, f.count}.encode(w);
                answer = 2u * f.count;
                gs->commands.push_back(MemoryAreaRead::code);
            } else {
                MultipleMemoryAreaRead{f.items}.encode(w);
                for (const auto& item : f.items) {
                    answer += 1;
                    offsets.push_back(static_cast<std::uint16_t>(answer));
                    answer += element_size(item.area_code);
                }
                gs->commands.push_back(MultipleMemoryAreaRead::code);
            }
            p.resize(w.written().size());
            gs->parameters.push_back(std::move(p));
            gs->item_offsets.push_back(std::move(offsets));
            gs->answer_sizes.push_back(answer);
        }
        gs->samples.resize(g.tags.size());
        gs->published.resize(g.tags.size());
        gs->have_published.assign(g.tags.size(), false);
        groups_.push_back(std::move(gs));
    }
    expired_.reserve(plc.window + 1);
}

PlcPoller::~PlcPoller() = default;

std::int64_t PlcPoller::now_ms() const {
    return std::chrono::duration_cast<std::chrono::milliseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
}

void PlcPoller::start() {
    if (running_) return;
    running_ = true;
    ++generation_;
    state_ = State::connecting;
    backoff_.reset();
    const auto now = PollClock::now();
    for (std::size_t g = 0; g < groups_.size(); ++g) {
        auto& gs = *groups_[g];
        gs.grid =
            TickGrid(now, std::chrono::duration_cast<PollClock::duration>(gs.cfg.interval), phase_);
        gs.need_full = true;
        gs.in_cycle = false;
        schedule(g);
    }
    open();
}

void PlcPoller::request_full() noexcept {
    for (auto& gs : groups_)
        gs->need_full = true;
}

void PlcPoller::stop() {
    if (!running_) return;
    running_ = false;
    ++generation_;
    for (auto& gs : groups_) {
        gs->timer.cancel();
        gs->in_cycle = false;
        gs->outstanding = 0;
        gs->have_published.assign(gs->have_published.size(), false);
    }
    timeout_timer_.cancel();
    armed_.reset();
    backoff_timer_.cancel();
    ready_.clear();
    expired_.clear();
    window_.take_all(PollClock::now(), expired_);
    expired_.clear();
    auto writes = std::move(writes_);
    writes_.clear();
    for (auto& op : writes) {
        WriteResponse r;
        r.id = op->id;
        r.error = "this instance no longer polls the PLC";
        events_.write_done(plc_, r);
    }
    close_socket();
    state_ = State::stopped;
}

void PlcPoller::schedule(std::size_t g) {
    auto& gs = *groups_[g];
    gs.timer.expires_at(gs.grid.next());
    gs.timer.async_wait([this, g, gen = generation_](boost::system::error_code ec) {
        if (gen != generation_ || ec) return;
        tick(g);
    });
}

void PlcPoller::tick(std::size_t g) {
    auto& gs = *groups_[g];
    // Drift-free: the next tick is on the grid, whatever this one cost. Ticks the loop
    // was too late for are skipped and counted.
    stats_.overruns += gs.grid.advance(PollClock::now());
    schedule(g);
    const bool can_poll = state_ == State::online ||
                          (state_ == State::connecting && plc_.transport == Transport::udp);
    if (!can_poll) return;
    if (gs.in_cycle) {
        ++stats_.overruns;
        return;
    }
    gs.in_cycle = true;
    gs.outstanding = gs.plan.frames.size();
    for (std::size_t f = 0; f < gs.plan.frames.size(); ++f) {
        Request r{Request::Kind::group_frame};
        r.group = g;
        r.frame = f;
        r.command = gs.commands[f];
        ready_.push_back(r);
    }
    pump();
}

void PlcPoller::enqueue(Request r) {
    ready_.push_back(r);
    pump();
}

void PlcPoller::pump() {
    while (!window_.full() && !ready_.empty()) {
        Request r = ready_.front();
        ready_.pop_front();
        if (!send(r)) continue;
        window_.add(r);
    }
    arm_timeout();
}

bool PlcPoller::send(Request& r) {
    const auto now = PollClock::now();
    Header h;
    h.destination = destination_;
    h.source = source_;
    h.service_id = window_.allocate(now);
    r.service_id = h.service_id;
    Bytes parameters;
    switch (r.kind) {
        case Request::Kind::group_frame:
        case Request::Kind::probe:
            parameters = groups_[r.group]->parameters[r.frame];
            break;
        case Request::Kind::handshake:
            return false;
        case Request::Kind::write:
        case Request::Kind::read_back:
            parameters = r.op->parameters;
            break;
    }
    const std::size_t offset = plc_.transport == Transport::tcp ? tcp_header_size : 0;
    auto n = encode_request(h, r.command, parameters, MutableBytes(scratch_).subspan(offset));
    if (!n) {
        complete(r, nullptr, n.error());
        return false;
    }
    r.deadline = now + plc_.timeout;
    if (plc_.transport == Transport::udp) {
        boost::system::error_code ec;
        udp_.send(asio::buffer(scratch_.data(), *n), 0, ec);
        // A refused or full send is a lost datagram: the timeout handles it.
    } else {
        ByteWriter w(MutableBytes(scratch_).first(tcp_header_size));
        write_tcp_header(w, TcpCommand::frame, *n);
        tx_.insert(tx_.end(), scratch_.begin(),
                   scratch_.begin() + static_cast<std::ptrdiff_t>(offset + *n));
        tcp_flush();
    }
    return true;
}

void PlcPoller::arm_timeout() {
    const auto earliest = window_.earliest_deadline();
    if (!earliest) return;
    // An earlier wait fires first and arms again for the rest.
    if (armed_ && *armed_ <= *earliest) return;
    armed_ = *earliest;
    timeout_timer_.expires_at(*earliest);
    timeout_timer_.async_wait([this, gen = generation_](boost::system::error_code ec) {
        if (gen != generation_ || ec) return;
        armed_.reset();
        on_timeout();
    });
}

void PlcPoller::on_timeout() {
    expired_.clear();
    window_.take_expired(PollClock::now(), expired_);
    for (std::size_t k = 0; k < expired_.size(); ++k) {
        Request& r = expired_[k];
        if (r.attempts < plc_.retries) {
            ++r.attempts;
            ++stats_.resends;
            // A new SID (the old one is in quarantine): a late answer to the old one
            // finds nothing in flight.
            if (send(r)) window_.add(r);
            continue;
        }
        ++stats_.timeouts;
        // The PLC is offline: this frame and every other one waiting fail with it.
        for (std::size_t j = k; j < expired_.size(); ++j)
            ready_.push_front(expired_[j]);
        go_offline(make_error_code(ClientError::timeout));
        return;
    }
    arm_timeout();
}

void PlcPoller::on_frame(Bytes frame) {
    auto v = decode_response(frame);
    if (!v) return;
    auto r = window_.take_answer(v->header, v->command, destination_.node, PollClock::now());
    if (!r) {
        // Late (after a resend), duplicated or not ours: dropped. But an answer to a frame
        // in flight from another node means the PLC is not the node it is addressed as
        // (dest, or its IP's last number): its frames then time out, and the status says
        // why (go_offline).
        if (window_.from_other_node(v->header, v->command, destination_.node)) {
            ++stats_.other_node_answers;
            answered_by_ = v->header.source;
        }
        return;
    }
    answered_by_.reset();
    ++stats_.frames;
    if (state_ != State::online) go_online();
    complete(*r, &*v, {});
    pump();
}

void PlcPoller::complete(Request& r, const ResponseView* response, std::error_code error) {
    std::error_code failure = error;
    if (!failure && !response->code.ok()) {
        failure = make_error_code(response->code.end_code());
        ++stats_.end_codes;
    }
    switch (r.kind) {
        case Request::Kind::probe:
        case Request::Kind::handshake:
            return;
        case Request::Kind::write:
        case Request::Kind::read_back:
            write_answered(r, response, failure);
            return;
        case Request::Kind::group_frame:
            break;
    }
    auto& gs = *groups_[r.group];
    if (!gs.in_cycle) return;
    const auto& f = gs.plan.frames[r.frame];
    if (!failure && response->data.size() != gs.answer_sizes[r.frame])
        failure = make_error_code(ClientError::malformed_response);
    for (std::size_t i : f.tags) {
        TagSample& s = gs.samples[i];
        if (failure) {
            s.error = failure;
            continue;
        }
        const auto& slot = gs.plan.slots[i];
        if (f.kind == PlannedFrame::Kind::read)
            decode_words(gs.cfg.tags[i], response->data, slot.offset, s);
        else
            decode_items(gs.cfg.tags[i], response->data, gs.item_offsets[r.frame].data(),
                         slot.offset, s);
        ++stats_.values;
    }
    if (--gs.outstanding == 0) finish_group(r.group);
}

void PlcPoller::finish_group(std::size_t g) {
    auto& gs = *groups_[g];
    gs.in_cycle = false;
    ++stats_.cycles;
    const auto now = PollClock::now();
    const bool full =
        gs.cfg.publish == Publish::always || gs.need_full || now - gs.last_full >= gs.cfg.integrity;
    if (full) {
        gs.need_full = false;
        gs.last_full = now;
    }
    for (std::size_t i = 0; i < gs.samples.size(); ++i) {
        TagSample& s = gs.samples[i];
        s.changed =
            !gs.have_published[i] || changed(gs.cfg.tags[i], gs.cfg.deadband, s, gs.published[i]);
        if (s.changed || full) {
            gs.published[i] = s;
            gs.have_published[i] = true;
        }
    }
    GroupSample sample{&plc_, &gs.cfg, gs.samples, now_ms(), full};
    events_.group_done(sample);
}

}  // namespace fins::bridge
