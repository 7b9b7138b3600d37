// PlcPoller: lifecycle, the groups' tick grids, the window of frames handed to the PLC's
// fins::Client, their answers and the end of a cycle. Writes are in poller_write.cpp,
// online/offline and back-off in poller_offline.cpp; the pure parts in poll_schedule and
// tag_decode. SIDs, retries, timeouts, sockets and the FINS/TCP handshake are the client's.
#include <algorithm>
#include <stdexcept>

#include "bridge/poll/poller_parts.hpp"
#include "bridge/poll/tag_decode.hpp"
#include "fins/commands/memory_area.hpp"

namespace fins::bridge {

namespace {

// The client of one PLC: its transport, address, timeout and retries. A configured
// dest is sent as written (node 0 too: W342's "local PLC"); none: the client derives it.
ClientOptions client_options(const Plc& plc) {
    ClientOptions o;
    o.host = plc.host;
    o.port = plc.port;
    o.protocol = plc.transport == Transport::tcp ? ClientOptions::Protocol::tcp
                                                 : ClientOptions::Protocol::udp;
    if (plc.dest) {
        o.destination = *plc.dest;
        o.destination_as_given = true;
    }
    o.timeout = plc.timeout;
    o.retries = plc.retries;
    return o;
}

}  // namespace

PlcPoller::PlcPoller(asio::io_context& io, const Plc& plc, double phase, PollerEvents& events,
                     std::uint64_t seed)
    : io_(io),
      plc_(plc),
      phase_(phase),
      events_(events),
      backoff_timer_(io),
      backoff_(plc.backoff_min, plc.backoff_max, seed) {
    // The configuration checked timeout and retries (config.cpp): create() only fails on
    // options out of range, which would be a bug here.
    auto client = Client::create(io, client_options(plc));
    if (!client) throw std::logic_error("fins-bridge: " + client.error().message());
    client_ = std::move(*client);
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
        for (const auto& t : g.tags)
            gs->plain_words.push_back(t.flag || t.type == TagType::bits || t.type == TagType::string
                                          ? std::uint8_t{0}
                                          : static_cast<std::uint8_t>(t.words));
        gs->samples.resize(g.tags.size());
        gs->published.resize(g.tags.size());
        gs->have_published.assign(g.tags.size(), false);
        groups_.push_back(std::move(gs));
    }
    in_flight_.reserve(plc.window);
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
        const auto interval = std::chrono::duration_cast<PollClock::duration>(gs.cfg.interval);
        gs.grid = TickGrid(now, interval, phase_, tick_alignment(interval));
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
    backoff_timer_.cancel();
    ready_.clear();
    in_flight_.clear();
    auto writes = std::move(writes_);
    writes_.clear();
    for (auto& op : writes) {
        WriteResponse r;
        r.id = op->id;
        r.error = "this instance no longer polls the PLC";
        events_.write_done(plc_, r);
    }
    // Requests still with the client fail with `canceled`: their completions belong to
    // the old generation and return early.
    client_->close();
    state_ = State::stopped;
}

NodeAddress PlcPoller::destination() const noexcept {
    return client_->destination();
}

PollerStats PlcPoller::stats() const noexcept {
    PollerStats s = stats_;
    const auto c = client_->stats();
    s.resends = c.retransmitted;
    s.other_node_answers = c.other_node_answers;
    return s;
}

// UDP: resolves and opens the socket, then polls (the first answer puts the PLC online);
// TCP: connects and does the handshake, then the PLC is online.
void PlcPoller::open() {
    client_->async_open([this, gen = generation_](std::error_code ec) {
        if (gen != generation_) return;
        if (ec) {
            go_offline(ec);
            return;
        }
        if (plc_.transport == Transport::tcp) go_online();
    });
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
    while (in_flight_.size() < plc_.window && !ready_.empty()) {
        Request r = ready_.front();
        ready_.pop_front();
        send(r);
    }
}

void PlcPoller::send(Request r) {
    Bytes parameters;
    switch (r.kind) {
        case Request::Kind::group_frame:
        case Request::Kind::probe:
            parameters = groups_[r.group]->parameters[r.frame];
            break;
        case Request::Kind::write:
        case Request::Kind::read_back:
            parameters = r.op->parameters;
            break;
    }
    r.token = ++next_token_;
    in_flight_.push_back(r);
    // The client copies the frame before returning; its answer comes as a view into the
    // receive buffer, decoded in place (no copy).
    client_->async_send_view(r.command, parameters,
                             [this, gen = generation_, token = r.token](Result<ResponseView> a) {
                                 if (gen != generation_) return;
                                 on_answer(token, a);
                             });
}

void PlcPoller::on_answer(std::uint64_t token, const Result<ResponseView>& answer) {
    const auto it = std::find_if(in_flight_.begin(), in_flight_.end(),
                                 [token](const Request& q) { return q.token == token; });
    if (it == in_flight_.end()) return;
    Request r = *it;
    *it = in_flight_.back();
    in_flight_.pop_back();
    if (!answer) {
        // Every attempt went unanswered (the client resent the same frame Plc::retries
        // times), the link failed or the PLC's port refused: the PLC is offline, and this
        // frame and every other one waiting fail with it.
        auto why = answer.error();
        // UDP: an ICMP port unreachable (nothing listens at the PLC's port) is a frame
        // that got no response, as the bridge has always reported it; the client only
        // says so sooner than the timeout would.
        if (plc_.transport == Transport::udp && why == std::errc::connection_refused)
            why = make_error_code(ClientError::timeout);
        if (why == make_error_code(ClientError::timeout)) ++stats_.timeouts;
        ready_.push_front(r);
        go_offline(why);
        return;
    }
    ++stats_.frames;
    if (state_ != State::online) go_online();
    const auto gen = generation_;
    complete(r, &*answer, {});
    if (gen == generation_) pump();
}

void PlcPoller::complete(Request& r, const ResponseView* response, std::error_code error) {
    std::error_code failure = error;
    if (!failure && !response->code.ok()) {
        failure = make_error_code(response->code.end_code());
        ++stats_.end_codes;
    }
    switch (r.kind) {
        case Request::Kind::probe:
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
        if (const auto n = gs.plain_words[i]; n > 0 && f.kind == PlannedFrame::Kind::read) {
            // decode_words() without reading the tag's configuration.
            s.error = {};
            const auto* word = response->data.data() + 2 * std::size_t{slot.offset};
            for (std::size_t k = 0; k < n; ++k, word += 2)
                s.value.words[k] = static_cast<std::uint16_t>((word[0] << 8) | word[1]);
        } else if (f.kind == PlannedFrame::Kind::read)
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
    // `always` publishes every tag of every cycle: nothing is compared, nothing kept.
    if (gs.cfg.publish != Publish::always) {
        for (std::size_t i = 0; i < gs.samples.size(); ++i) {
            TagSample& s = gs.samples[i];
            s.changed = !gs.have_published[i] ||
                        changed(gs.cfg.tags[i], gs.cfg.deadband, s, gs.published[i]);
            if (s.changed || full) {
                gs.published[i] = s;
                gs.have_published[i] = true;
            }
        }
    }
    GroupSample sample{&plc_, &gs.cfg, gs.samples, now_ms(), full};
    events_.group_done(sample);
}

}  // namespace fins::bridge
