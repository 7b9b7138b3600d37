#include "bridge/poller.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/write.hpp>

#include "fins/commands/memory_area.hpp"
#include "fins/node_address.hpp"
#include "fins/tcp.hpp"
#include "fins/values.hpp"

namespace fins::bridge {

using Clock = std::chrono::steady_clock;

struct PlcPoller::GroupState {
    GroupState(asio::io_context& io, const Group& g) : cfg(g), timer(io) {}
    const Group& cfg;
    Plan plan;
    std::vector<std::vector<std::uint8_t>> parameters;     // encoded once per frame
    std::vector<std::vector<std::uint16_t>> item_offsets;  // 01 04: byte offset of each value
    std::vector<std::size_t> answer_sizes;                 // expected response data bytes
    std::vector<TagSample> samples;
    std::vector<TagSample> published;
    std::vector<bool> have_published;
    asio::steady_timer timer;
    Clock::time_point next;
    std::size_t outstanding = 0;
    bool in_cycle = false;
    bool need_full = true;
    Clock::time_point last_full;
    std::int64_t ts_ms = 0;
};

struct PlcPoller::WriteOp {
    std::string id;
    const Tag* tag = nullptr;
    std::vector<std::uint8_t> parameters;
    std::uint16_t end_code = 0;
};

namespace {

std::uint16_t word_at(Bytes data, std::size_t index) {
    return static_cast<std::uint16_t>((data[2 * index] << 8) | data[2 * index + 1]);
}

// The tag's value from an 01 01 answer whose words start `offset` words before it.
void decode_words(const Tag& tag, Bytes data, std::size_t offset, TagSample& s) {
    s.error = {};
    s.value.text.clear();
    if (tag.type == TagType::boolean) {
        s.value.words = {};
        s.value.words[0] =
            static_cast<std::uint16_t>((word_at(data, offset) >> tag.address.bit.value_or(0)) & 1);
        return;
    }
    if (tag.type == TagType::string) {
        std::uint16_t words[max_read_words];
        for (std::size_t i = 0; i < tag.words; ++i)
            words[i] = word_at(data, offset + i);
        s.value.text = words_to_string({words, tag.words});
        if (s.value.text.size() > tag.length) s.value.text.resize(tag.length);
        return;
    }
    s.value.words = {};
    for (std::size_t i = 0; i < tag.words; ++i)
        s.value.words[i] = word_at(data, offset + i);
}

bool is_end_code(std::error_code ec) {
    return ec.category() == end_code_category();
}

}  // namespace

PlcPoller::PlcPoller(asio::io_context& io, const Plc& plc, double phase, PollerEvents& events,
                     std::uint64_t seed)
    : io_(io),
      plc_(plc),
      phase_(phase),
      events_(events),
      random_(seed),
      udp_(io),
      tcp_(io),
      timeout_timer_(io),
      backoff_timer_(io) {
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
            } else {
                MultipleMemoryAreaRead{f.items}.encode(w);
                for (const auto& item : f.items) {
                    answer += 1;
                    offsets.push_back(static_cast<std::uint16_t>(answer));
                    answer += element_size(item.area_code);
                }
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
    backoff_attempt_ = 0;
    const auto now = Clock::now();
    for (std::size_t g = 0; g < groups_.size(); ++g) {
        auto& gs = *groups_[g];
        const auto interval = std::chrono::duration_cast<Clock::duration>(gs.cfg.interval);
        gs.next = now + std::chrono::duration_cast<Clock::duration>(interval * phase_);
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
    in_flight_.clear();
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

void PlcPoller::close_socket() {
    ++socket_generation_;
    boost::system::error_code ignored;
    if (udp_.is_open()) udp_.close(ignored);
    if (tcp_.is_open()) tcp_.close(ignored);
    rx_used_ = 0;
    tx_.clear();
    writing_ = false;
}

void PlcPoller::open() {
    boost::system::error_code ec;
    if (plc_.transport == Transport::udp) {
        if (!udp_peer_) {
            asio::ip::udp::resolver resolver(io_);
            auto r = resolver.resolve(plc_.host, std::to_string(plc_.port), ec);
            if (ec || r.empty()) {
                go_offline(std::make_error_code(std::errc::host_unreachable));
                last_error_ = fmt::format("cannot resolve {}: {}", plc_.host, ec.message());
                return;
            }
            udp_peer_ = r.begin()->endpoint();
        }
        if (!udp_.is_open()) {
            udp_.open(udp_peer_->protocol(), ec);
            if (!ec) udp_.connect(*udp_peer_, ec);
            if (!ec) udp_.non_blocking(true, ec);
            if (ec) {
                close_socket();
                go_offline(std::make_error_code(std::errc::network_unreachable));
                return;
            }
            const auto local = udp_.local_endpoint(ec).address();
            const auto peer = udp_peer_->address();
            const auto bytes = [](const asio::ip::address& a) {
                std::vector<std::uint8_t> b;
                if (a.is_v4()) {
                    auto x = a.to_v4().to_bytes();
                    b.assign(x.begin(), x.end());
                } else {
                    auto x = a.to_v6().to_bytes();
                    b.assign(x.begin(), x.end());
                }
                return b;
            };
            destination_ = plc_.dest.value_or(NodeAddress{0, node_from_ip(bytes(peer)), 0});
            source_ = {0, node_from_ip(bytes(local)), 0};
            if (source_.node == destination_.node || source_.node == 0) source_.node = 254;
            udp_read();
        }
        return;
    }
    tcp_connect();
}

void PlcPoller::udp_read() {
    udp_.async_receive(asio::buffer(rx_), [this, gen = socket_generation_](
                                              boost::system::error_code ec, std::size_t n) {
        if (gen != socket_generation_ || ec == asio::error::operation_aborted) return;
        // connection_refused: an ICMP port unreachable for an earlier datagram (a stopped
        // PLC). The frame's timeout takes the PLC offline; keep listening.
        if (!ec) on_frame(Bytes(rx_.data(), n));
        udp_read();
    });
}

void PlcPoller::tcp_connect() {
    close_socket();
    state_ = state_ == State::online ? State::offline : state_;
    const auto gen = generation_;
    asio::ip::tcp::resolver resolver(io_);
    boost::system::error_code ec;
    auto r = resolver.resolve(plc_.host, std::to_string(plc_.port), ec);
    if (ec || r.empty()) {
        go_offline(std::make_error_code(std::errc::host_unreachable));
        return;
    }
    tcp_peer_ = r.begin()->endpoint();
    tcp_.async_connect(*tcp_peer_, [this, gen](boost::system::error_code e) {
        if (gen != generation_ || e == asio::error::operation_aborted) return;
        if (e) {
            go_offline(std::make_error_code(std::errc::connection_refused));
            return;
        }
        boost::system::error_code ignored;
        tcp_.set_option(asio::ip::tcp::no_delay(true), ignored);
        std::array<std::uint8_t, 20> hello{};
        ByteWriter w(hello);
        write_node_address_request(w, 0);  // 0: the server allocates our node
        tx_.insert(tx_.end(), hello.begin(), hello.end());
        tcp_flush();
        // The handshake must finish within the frame timeout.
        Request probe{Request::Kind::handshake};
        probe.service_id = 0;
        probe.deadline = Clock::now() + plc_.timeout;
        probe.attempts = plc_.retries;  // no resend: the whole connection is retried
        in_flight_.push_back(probe);
        arm_timeout();
        tcp_read();
    });
}

void PlcPoller::tcp_read() {
    tcp_.async_read_some(
        asio::buffer(rx_.data() + rx_used_, rx_.size() - rx_used_),
        [this, gen = generation_](boost::system::error_code ec, std::size_t n) {
            if (gen != generation_ || ec == asio::error::operation_aborted) return;
            if (ec) {
                go_offline(make_error_code(ClientError::connection_closed));
                return;
            }
            rx_used_ += n;
            std::size_t at = 0;
            while (true) {
                auto p = parse_tcp_frame(Bytes(rx_.data() + at, rx_used_ - at));
                if (p.status == TcpParse::Status::need_more) break;
                if (p.status == TcpParse::Status::error) {
                    go_offline(make_error_code(p.error));
                    return;
                }
                at += p.consumed;
                const auto command = static_cast<TcpCommand>(p.packet.command);
                if (p.packet.error != 0) {
                    go_offline(make_error_code(static_cast<TcpError>(p.packet.error)));
                    return;
                }
                if (command == TcpCommand::node_address_response) {
                    auto r = decode_node_address_response(p.packet.data);
                    if (!r) {
                        go_offline(make_error_code(ClientError::handshake_failed));
                        return;
                    }
                    source_ = {0, r->client_node, 0};
                    destination_ = plc_.dest.value_or(NodeAddress{0, r->server_node, 0});
                    std::erase_if(in_flight_, [](const Request& q) {
                        return q.kind == Request::Kind::handshake;
                    });
                    go_online();
                } else if (command == TcpCommand::frame) {
                    on_frame(p.packet.data);
                    if (gen != generation_ || !tcp_.is_open()) return;
                }
            }
            std::memmove(rx_.data(), rx_.data() + at, rx_used_ - at);
            rx_used_ -= at;
            tcp_read();
        });
}

void PlcPoller::tcp_flush() {
    if (writing_ || tx_.empty() || !tcp_.is_open()) return;
    std::swap(tx_, tx_busy_);
    tx_.clear();
    writing_ = true;
    asio::async_write(tcp_, asio::buffer(tx_busy_),
                      [this, gen = generation_](boost::system::error_code ec, std::size_t) {
                          if (gen != generation_ || ec == asio::error::operation_aborted) return;
                          writing_ = false;
                          tx_busy_.clear();
                          if (ec) {
                              go_offline(make_error_code(ClientError::connection_closed));
                              return;
                          }
                          tcp_flush();
                      });
}

void PlcPoller::schedule(std::size_t g) {
    auto& gs = *groups_[g];
    gs.timer.expires_at(gs.next);
    gs.timer.async_wait([this, g, gen = generation_](boost::system::error_code ec) {
        if (gen != generation_ || ec) return;
        tick(g);
    });
}

void PlcPoller::tick(std::size_t g) {
    auto& gs = *groups_[g];
    const auto interval = std::chrono::duration_cast<Clock::duration>(gs.cfg.interval);
    const auto now = Clock::now();
    // Drift-free: the next tick is on the grid, whatever this one cost. Ticks the loop
    // was too late for are skipped and counted.
    gs.next += interval;
    if (gs.next <= now) {
        const auto missed = (now - gs.next) / interval + 1;
        stats_.overruns += static_cast<std::uint64_t>(missed);
        gs.next += interval * missed;
    }
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
        if (!send(r)) continue;
        in_flight_.push_back(r);
    }
    arm_timeout();
}

bool PlcPoller::send(Request& r) {
    // A service ID not in flight (the window is at most 64 of 256).
    for (int i = 0; i < 256; ++i) {
        const std::uint8_t sid = next_service_id_++;
        if (std::none_of(in_flight_.begin(), in_flight_.end(),
                         [sid](const Request& q) { return q.service_id == sid; })) {
            r.service_id = sid;
            break;
        }
    }
    Header h;
    h.destination = destination_;
    h.source = source_;
    h.service_id = r.service_id;
    CommandCode code = MemoryAreaRead::code;
    Bytes parameters;
    switch (r.kind) {
        case Request::Kind::group_frame:
        case Request::Kind::probe: {
            auto& gs = *groups_[r.group];
            if (gs.plan.frames[r.frame].kind == PlannedFrame::Kind::multiple_read)
                code = MultipleMemoryAreaRead::code;
            parameters = gs.parameters[r.frame];
            break;
        }
        case Request::Kind::handshake:
            return false;
        case Request::Kind::write:
            code = MemoryAreaWrite::code;
            parameters = r.op->parameters;
            break;
        case Request::Kind::read_back: {
            std::array<std::uint8_t, 6> p{};
            ByteWriter w(p);
            MemoryAreaRead{r.op->tag->read_start, static_cast<std::uint16_t>(r.op->tag->words)}
                .encode(w);
            r.op->parameters.assign(p.begin(), p.end());
            parameters = r.op->parameters;
            break;
        }
    }
    const std::size_t offset = plc_.transport == Transport::tcp ? tcp_header_size : 0;
    auto n = encode_request(h, code, parameters, MutableBytes(scratch_).subspan(offset));
    if (!n) {
        complete(r, nullptr, n.error());
        return false;
    }
    r.deadline = Clock::now() + plc_.timeout;
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
    if (in_flight_.empty()) return;
    auto earliest = in_flight_.front().deadline;
    for (const auto& r : in_flight_)
        earliest = std::min(earliest, r.deadline);
    // An earlier wait fires first and arms again for the rest.
    if (armed_ && *armed_ <= earliest) return;
    armed_ = earliest;
    timeout_timer_.expires_at(earliest);
    timeout_timer_.async_wait([this, gen = generation_](boost::system::error_code ec) {
        if (gen != generation_ || ec) return;
        armed_.reset();
        on_timeout();
    });
}

void PlcPoller::on_timeout() {
    const auto now = Clock::now();
    std::vector<Request> expired;
    for (std::size_t i = 0; i < in_flight_.size();) {
        if (in_flight_[i].deadline <= now) {
            expired.push_back(in_flight_[i]);
            in_flight_[i] = in_flight_.back();
            in_flight_.pop_back();
        } else {
            ++i;
        }
    }
    for (std::size_t k = 0; k < expired.size(); ++k) {
        Request& r = expired[k];
        if (r.attempts < plc_.retries) {
            ++r.attempts;
            ++stats_.resends;
            // A new service ID: a late answer to the old one is then simply unmatched.
            if (send(r)) in_flight_.push_back(r);
            continue;
        }
        ++stats_.timeouts;
        // The PLC is offline: this frame and every other one waiting fail with it.
        in_flight_.insert(in_flight_.end(), expired.begin() + static_cast<std::ptrdiff_t>(k),
                          expired.end());
        go_offline(make_error_code(ClientError::timeout));
        return;
    }
    arm_timeout();
}

void PlcPoller::on_frame(Bytes frame) {
    auto v = decode_response(frame);
    if (!v) return;
    const auto sid = v->header.service_id;
    auto it = std::find_if(in_flight_.begin(), in_flight_.end(), [sid](const Request& r) {
        return r.service_id == sid && r.kind != Request::Kind::handshake;
    });
    if (it == in_flight_.end()) return;  // late (after a resend) or not ours
    Request r = *it;
    *it = in_flight_.back();
    in_flight_.pop_back();
    ++stats_.frames;
    if (state_ != State::online) go_online();
    complete(r, &*v, {});
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
            if (failure) {
                finish_write(*r.op, failure, nullptr);
            } else {
                r.op->end_code = response->code.raw();
                Request back{Request::Kind::read_back};
                back.op = r.op;
                ready_.push_front(back);
            }
            return;
        case Request::Kind::read_back:
            finish_write(*r.op, failure, response);
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
        const Tag& tag = gs.cfg.tags[i];
        if (failure) {
            s.error = failure;
            continue;
        }
        const auto& slot = gs.plan.slots[i];
        if (f.kind == PlannedFrame::Kind::read) {
            decode_words(tag, response->data, slot.offset, s);
        } else {
            const auto& offsets = gs.item_offsets[r.frame];
            s.error = {};
            s.value.words = {};
            if (tag.flag) {
                s.value.words[0] = response->data[offsets[slot.offset]] & 1;
            } else {
                for (std::size_t k = 0; k < tag.words; ++k) {
                    const auto at = offsets[slot.offset + k];
                    s.value.words[k] = static_cast<std::uint16_t>((response->data[at] << 8) |
                                                                  response->data[at + 1u]);
                }
                if (tag.type == TagType::boolean)
                    s.value.words[0] = (s.value.words[0] >> tag.address.bit.value_or(0)) & 1;
            }
        }
        ++stats_.values;
    }
    if (--gs.outstanding == 0) finish_group(r.group);
}

void PlcPoller::finish_group(std::size_t g) {
    auto& gs = *groups_[g];
    gs.in_cycle = false;
    ++stats_.cycles;
    const auto now = Clock::now();
    bool full =
        gs.cfg.publish == Publish::always || gs.need_full || now - gs.last_full >= gs.cfg.integrity;
    if (full) {
        gs.need_full = false;
        gs.last_full = now;
    }
    for (std::size_t i = 0; i < gs.samples.size(); ++i) {
        TagSample& s = gs.samples[i];
        const TagSample& p = gs.published[i];
        const Tag& tag = gs.cfg.tags[i];
        bool changed = true;
        if (gs.have_published[i]) {
            if (s.error || p.error) {
                changed = s.error != p.error;
            } else if (tag.type == TagType::string) {
                changed = s.value.text != p.value.text;
            } else {
                const double band = tag.deadband.value_or(gs.cfg.deadband);
                if (band > 0)
                    changed =
                        std::abs(numeric(tag.type, s.value) - numeric(tag.type, p.value)) > band;
                else
                    changed = s.value.words != p.value.words;
            }
        }
        s.changed = changed;
        if (changed || full) {
            gs.published[i] = s;
            gs.have_published[i] = true;
        }
    }
    GroupSample sample{&plc_, &gs.cfg, gs.samples, now_ms(), full};
    events_.group_done(sample);
}

std::optional<std::string> PlcPoller::write(const Tag& tag, const Encoded& value, std::string id) {
    if (!running_) return "this instance does not poll the PLC";
    if (state_ != State::online)
        return last_error_.empty() ? std::string("PLC offline") : "PLC offline: " + last_error_;
    if (writes_.size() >= max_pending_writes)
        return fmt::format("{} writes already wait for this PLC", max_pending_writes);
    auto op = std::make_unique<WriteOp>();
    op->id = std::move(id);
    op->tag = &tag;
    std::vector<std::uint8_t> data;
    MemoryAddress start = tag.read_start;
    std::uint16_t count = static_cast<std::uint16_t>(tag.words);
    if (tag.type == TagType::boolean) {
        start = *to_memory_address(tag.address, Access::bit);
        count = 1;
        data.push_back(value.bit ? 1 : 0);
    } else if (tag.type == TagType::string) {
        auto words = string_to_words(value.text, tag.words);
        if (!words) return describe(words.error());
        data = words_to_bytes(*words);
    } else {
        data = words_to_bytes({value.words.data(), value.count});
    }
    op->parameters.resize(max_parameter_size);
    ByteWriter w(op->parameters);
    MemoryAreaWrite{start, count, data}.encode(w);
    op->parameters.resize(w.written().size());
    Request r{Request::Kind::write};
    r.op = op.get();
    writes_.push_back(std::move(op));
    enqueue(r);
    return std::nullopt;
}

void PlcPoller::finish_write(WriteOp& op, std::error_code error, const ResponseView* response) {
    WriteResponse r;
    r.id = op.id;
    if (error) {
        r.ok = false;
        r.error = error_text(error);
        if (is_end_code(error))
            r.end_code = static_cast<std::uint16_t>(error.value());
        else if (op.end_code != 0 || response != nullptr)
            r.end_code = op.end_code;
    } else {
        r.end_code = op.end_code;
        if (response->data.size() != 2 * op.tag->words) {
            r.ok = false;
            r.error = "the read back did not fit the tag: " +
                      describe(make_error_code(ClientError::malformed_response));
        } else {
            TagSample s;
            decode_words(*op.tag, response->data, 0, s);
            r.ok = true;
            r.value = to_json(op.tag->type, s.value);
        }
    }
    auto it = std::find_if(writes_.begin(), writes_.end(),
                           [&op](const auto& p) { return p.get() == &op; });
    std::unique_ptr<WriteOp> keep;
    if (it != writes_.end()) {
        keep = std::move(*it);
        writes_.erase(it);
    }
    events_.write_done(plc_, r);
}

void PlcPoller::go_online() {
    if (state_ == State::online) return;
    state_ = State::online;
    backoff_attempt_ = 0;
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
    // Everything waiting fails now: the cycles publish their tags with this error.
    auto failed = std::move(in_flight_);
    in_flight_.clear();
    for (auto& r : ready_)
        failed.push_back(r);
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
    const auto cap = std::min<double>(static_cast<double>(plc_.backoff_max.count()),
                                      static_cast<double>(plc_.backoff_min.count()) *
                                          std::pow(2.0, std::min(backoff_attempt_, 30u)));
    ++backoff_attempt_;
    std::uniform_real_distribution<double> jitter(0.0, cap);
    backoff_timer_.expires_after(
        std::chrono::milliseconds(static_cast<std::int64_t>(jitter(random_))));
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
        probe.attempts = plc_.retries;  // one try; a failure backs off again
        enqueue(probe);
    });
}

}  // namespace fins::bridge
