#include "bridge/bridge.hpp"

#include <cmath>
#include <random>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace fins::bridge {

namespace {

using Clock = std::chrono::steady_clock;

// One handler per alternative for std::visit: a ParsedCommand alternative without one does not
// compile.
template <class... F>
struct overloaded : F... {
    using F::operator()...;
};
template <class... F>
overloaded(F...) -> overloaded<F...>;

std::int64_t epoch_ms() {
    return std::chrono::duration_cast<std::chrono::milliseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
}

}  // namespace

Bridge::Bridge(asio::io_context& io, const BridgeConfig& config,
               std::unique_ptr<PayloadFormat> format, std::unique_ptr<Ownership> ownership)
    : io_(io),
      config_(config),
      format_(std::move(format)),
      ownership_(std::move(ownership)),
      report_timer_(io) {
    sink_ = [this](Message&& m) { publish(std::move(m)); };
    std::random_device seed;
    std::size_t index = 0;
    for (const auto& p : config_.plcs) {
        auto poller = std::make_unique<PlcPoller>(io_, p, spread_phase(index++), *this,
                                                  (std::uint64_t{seed()} << 32) | seed());
        by_plc_.emplace(&p, PlcEntry{poller.get(), nullptr});
        pollers_.emplace(p.name, std::move(poller));
    }
    ownership_->on_change([this] { reconcile(); });
}

Bridge::~Bridge() = default;

bool Bridge::start(std::string& error) {
    const bool session = format_->own_session();
    // Everything below runs on the io_context's thread, the MQTT callbacks included
    // (mqtt.hpp): the births of a connection are published from its CONNACK, before any
    // message of the pollers can follow them on it.
    MqttClient::Handlers h;
    if (!session) h.connected = [this](std::uint64_t generation) { births(generation); };
    const auto message = [this](std::string topic, std::string payload, bool retained) {
        incoming(std::move(topic), std::move(payload), retained);
    };
    h.message = message;
    h.disconnected = [this] {
        if (!stopped_) ownership_->connection_lost();
    };
    auto subscriptions = ownership_->subscriptions();
    if (!session) {
        const auto more = format_->subscriptions();
        subscriptions.insert(subscriptions.end(), more.begin(), more.end());
    }
    // The connection that carries JSON write commands is a persistent session: writes
    // published while the bridge reconnects or is stopped are queued by the broker and
    // delivered on the next connect (docs/bridge.md "Writes"). Sparkplug's Edge Node session
    // must start clean (its specification); its status connection stays as it was.
    mqtt_ = std::make_unique<MqttClient>(io_, config_.mqtt, format_->bridge_status(false),
                                         format_->bridge_status(true), std::move(subscriptions),
                                         std::move(h), !session);
    if (!mqtt_->start(error)) return false;
    if (session) {
        // Sparkplug's Edge Node session: its own client id, its NDEATH as the Will.
        Mqtt sc = config_.mqtt;
        sc.client_id += "-session";
        MqttClient::Handlers sh;
        sh.connected = [this](std::uint64_t generation) { births(generation); };
        sh.message = message;
        sh.will = [this] { return format_->session_will(); };
        session_ = std::make_unique<MqttClient>(io_, sc, Message{}, Message{},
                                                format_->subscriptions(), std::move(sh));
        if (!session_->start(error)) return false;
    }
    reconcile();
    last_report_ = Clock::now();
    report();
    return true;
}

void Bridge::births(std::uint64_t generation) {
    // Only for the connection that carries the format's messages now: a connection that is
    // already gone (or replaced) gets no births, and nothing of the format goes out on the
    // new one before its own (Sparkplug: no DDATA before this session's NBIRTH).
    const MqttClient* carrier = session_ ? session_.get() : mqtt_.get();
    if (stopped_ || carrier == nullptr || carrier->generation() != generation ||
        !carrier->connected())
        return;
    format_->connected(sink_);
    for (const auto& [name, st] : statuses_)
        format_->status(st, sink_);
    for (auto& [name, p] : pollers_)
        p->request_full();
}

void Bridge::stop() {
    if (stopped_) return;
    stopped_ = true;
    report_timer_.cancel();
    for (auto& [name, p] : pollers_)
        p->stop();
    if (session_) session_->stop(format_->session_goodbye());
    if (mqtt_) mqtt_->stop(format_->bridge_status(false));
}

bool Bridge::looking_up() const noexcept {
    return (mqtt_ && mqtt_->looking_up()) || (session_ && session_->looking_up());
}

void Bridge::reconcile() {
    if (stopped_) return;
    for (auto& [name, p] : pollers_) {
        const bool mine = ownership_->owns(name);
        if (mine && !p->running()) {
            p->start();
        } else if (!mine && p->running()) {
            p->stop();
            statuses_.erase(name);
            by_plc_[&p->plc()].status = nullptr;
            format_->released(p->plc(), sink_);
        }
    }
    // After the pollers: a PLC this instance now owns is started before its writes.
    release_held();
}

void Bridge::publish(Message&& m) {
    if (session_)
        session_->publish(m);
    else if (mqtt_)
        mqtt_->publish(m);
}

void Bridge::group_done(const GroupSample& sample) {
    format_->values(sample, sink_);
    // By the PLC's address, not its name: this runs for every cycle of every PLC.
    const auto e = by_plc_.find(sample.plc);
    if (e == by_plc_.end() || e->second.status == nullptr) return;
    if (auto next = tag_failures_.cycle(sample, *e->second.status, e->second.poller->destination()))
        status_changed(*next);
}

void Bridge::status_changed(const PlcStatus& status) {
    auto& kept = statuses_[status.plc->name];
    kept = status;
    if (const auto e = by_plc_.find(status.plc); e != by_plc_.end()) e->second.status = &kept;
    if (!status.failing) tag_failures_.reset(status.plc);
    if (status.online && !status.failing)
        spdlog::info("PLC {} online", status.plc->name);
    else
        spdlog::warn("PLC {} {}: {}", status.plc->name, status.online ? "failing" : "offline",
                     status.last_error);
    format_->status(status, sink_);
}

void Bridge::write_done(const Plc& plc, const WriteResponse& response) {
    auto& e = remember(plc.name, response.id);
    e.done = true;
    e.response = response;
    format_->write_response(plc, response, sink_);
}

void Bridge::answer(const Plc& plc, const WriteResponse& r) {
    if (!r.id.empty()) {
        auto& e = remember(plc.name, r.id);
        e.done = true;
        e.response = r;
    }
    format_->write_response(plc, r, sink_);
}

Bridge::IdMemory::Entry& Bridge::remember(const std::string& plc, const std::string& id) {
    auto& m = ids_[plc];
    auto [it, fresh] = m.entries.try_emplace(id);
    if (fresh) {
        m.order.push_back(id);
        while (m.order.size() > config_.write.id_memory) {
            if (m.order.front() != id) m.entries.erase(m.order.front());
            m.order.pop_front();
        }
    }
    return m.entries.find(id)->second;
}

void Bridge::incoming(std::string topic, std::string payload, bool retained) {
    // On the io_context's thread (the MQTT client's callbacks run there): handled now.
    if (!stopped_) handle(topic, payload, retained, Clock::now());
}

void Bridge::handle(const std::string& topic, const std::string& payload, bool retained,
                    Clock::time_point arrival) noexcept {
    // The failure boundary of one message: whatever handling it throws ends here, as a
    // refusal where one can be answered, a log line and a count (docs/bridge.md).
    std::optional<ParsedCommand> parsed;
    try {
        command(topic, payload, retained, arrival, parsed);
    } catch (const std::exception& e) {
        failed(topic, retained, parsed, e.what());
    } catch (...) {
        failed(topic, retained, parsed, "unknown exception");
    }
}

void Bridge::failed(const std::string& topic, bool retained,
                    const std::optional<ParsedCommand>& parsed, std::string_view what) noexcept {
    ++failed_commands_;
    try {
        const auto now = Clock::now();
        if (now - last_failure_log_ >= std::chrono::seconds(1)) {
            spdlog::error("handling a message on {} failed: {} ({} more failures not logged)",
                          topic, what, failures_unlogged_);
            last_failure_log_ = now;
            failures_unlogged_ = 0;
        } else {
            ++failures_unlogged_;
        }
        if (!parsed) return;  // it failed before it was understood: nothing to answer
        const auto reason = fmt::format("internal error: {}", what);
        std::visit(overloaded{
                       [&](const WriteCommand& w) {
                           // Not answered when the write was started (its answer will come);
                           // a repeated id gets the first answer (refuse()).
                           if (const auto m = ids_.find(w.plc); m != ids_.end())
                               if (const auto e = m->second.entries.find(w.id);
                                   e != m->second.entries.end() && !e->second.done)
                                   return;
                           refuse(Refusal{w.plc, WriteResponse{w.id, false, std::nullopt,
                                                               std::nullopt, reason}},
                                  retained);
                       },
                       [&](const Refusal& r) {
                           refuse(Refusal{r.plc, WriteResponse{r.response.id, false, std::nullopt,
                                                               std::nullopt, reason}},
                                  retained);
                       },
                       [&](const NodeRebirth&) { format_->rejected(topic, reason); },
                       [&](const Rejected&) { format_->rejected(topic, reason); },
                   },
                   *parsed);
    } catch (...) {
        // The refusal failed too: the count above is all that is left of it.
    }
}

std::size_t Bridge::remembered_ids() const noexcept {
    std::size_t n = 0;
    for (const auto& [plc, m] : ids_)
        n += m.entries.size();
    return n;
}

void Bridge::release_held() {
    if (held_.empty() || !ownership_->joined()) return;
    // In the order they came, before any command that comes after them.
    while (!held_.empty() && ownership_->joined() && !stopped_) {
        Held h = std::move(held_.front());
        held_.pop_front();
        handle(h.topic, h.payload, h.retained, h.arrival);
    }
}

void Bridge::command(const std::string& topic, const std::string& payload, bool retained,
                     Clock::time_point arrival, std::optional<ParsedCommand>& parsed) {
    if (ownership_->on_message(topic, payload)) return;  // membership
    if (!ownership_->joined()) {
        // Who owns the PLC is not known yet: the command waits (its time here counts against
        // ttl_s), at most max_pending_commands of them.
        if (held_.size() >= max_pending_commands) {
            ++dropped_commands_;
            spdlog::warn("command on {} dropped: {} commands wait for this instance to join", topic,
                         held_.size());
            return;
        }
        held_.push_back({topic, payload, retained, arrival});
        return;
    }
    parsed = format_->parse(topic, payload, retained);
    if (!parsed) return;
    if (command_hook_) command_hook_(*parsed);
    std::visit(overloaded{
                   [&](const WriteCommand& w) { execute(w, arrival); },
                   [&](const Refusal& r) { refuse(r, retained); },
                   [&](const NodeRebirth&) { rebirth(); },
                   [&](const Rejected& r) { format_->rejected(topic, r.reason); },
               },
               *parsed);
}

void Bridge::rebirth() {
    // A host application asks for the whole birth sequence again (Sparkplug NCMD). The
    // topic is this instance's own: no ownership check.
    format_->connected(sink_);
    for (const auto& [name, st] : statuses_)
        format_->status(st, sink_);
}

void Bridge::refuse(const Refusal& r, bool retained) {
    // Its owner answers. A retained command arrives as this instance subscribes, before it
    // has joined; it is refused, never executed, by the instance that owns the PLC once
    // joined (docs/bridge.md "Several instances").
    if (!ownership_->owns(r.plc) && !(retained && ownership_->owns_once_joined(r.plc))) return;
    const auto it = pollers_.find(r.plc);
    if (it == pollers_.end()) {
        // A PLC the configuration does not have (the topic is the sender's): refused, and
        // nothing is remembered for it (the id memory is per configured PLC, bounded).
        Plc unknown;
        unknown.name = r.plc;
        WriteResponse response = r.response;
        response.ok = false;
        format_->write_response(unknown, response, sink_);
        return;
    }
    const Plc& plc = it->second->plc();
    // A repeated id is answered as the first time, even when refused.
    if (!r.response.id.empty()) {
        auto& m = ids_[plc.name];
        if (auto e = m.entries.find(r.response.id); e != m.entries.end() && e->second.done) {
            format_->write_response(plc, e->second.response, sink_);
            return;
        }
    }
    answer(plc, r.response);
}

void Bridge::execute(const WriteCommand& w, Clock::time_point arrival) {
    if (!ownership_->owns(w.plc)) return;  // its owner answers
    auto it = pollers_.find(w.plc);
    if (it == pollers_.end()) {
        // A PLC the configuration does not have (the topic is the sender's): refused, and
        // nothing is remembered for it (the id memory is per configured PLC, bounded).
        Plc unknown;
        unknown.name = w.plc;
        format_->write_response(
            unknown,
            WriteResponse{w.id, false, std::nullopt, std::nullopt,
                          fmt::format("no PLC named '{}' in this bridge's configuration", w.plc)},
            sink_);
        return;
    }
    const Plc& plc = it->second->plc();
    {
        auto& m = ids_[plc.name];
        if (auto e = m.entries.find(w.id); e != m.entries.end()) {
            if (e->second.done) format_->write_response(plc, e->second.response, sink_);
            return;  // running: its answer is on its way
        }
    }
    const auto refuse = [&](std::string error) {
        answer(plc, WriteResponse{w.id, false, std::nullopt, std::nullopt, std::move(error)});
    };
    const auto ttl = config_.write.ttl;
    const auto skew = config_.write.ts_skew;
    // Compared on this side so that no ts, however far off, overflows.
    const std::int64_t now_ms = epoch_ms();
    if (w.ts_ms && *w.ts_ms > now_ms + skew.count())
        return refuse(fmt::format("ts is more than {} ms ahead of the bridge's clock (ts_skew_s)",
                                  skew.count()));
    if (w.ts_ms && *w.ts_ms < now_ms - ttl.count())
        return refuse(fmt::format("command older than the TTL ({} ms)", ttl.count()));
    if (Clock::now() - arrival > ttl)
        return refuse(fmt::format("command waited longer than the TTL ({} ms)", ttl.count()));
    const Tag* tag = plc.find_tag(w.tag);
    if (tag == nullptr) return refuse(fmt::format("no tag '{}' on PLC '{}'", w.tag, plc.name));
    if (!tag->writable) return refuse(fmt::format("tag '{}' is not writable", w.tag));
    Encoded value;
    if (auto e = encode_value(tag->type, tag->length, tag->range, w.value, value))
        return refuse(*e);
    if (auto e = it->second->write(*tag, value, w.id)) return refuse(*e);
    remember(plc.name, w.id);  // running
}

void Bridge::report() {
    report_timer_.expires_after(config_.stats);
    report_timer_.async_wait([this](boost::system::error_code ec) {
        if (ec || stopped_) return;
        PollerStats t{};
        std::size_t online = 0;
        std::size_t polled = 0;
        for (const auto& [name, p] : pollers_) {
            const auto& s = p->stats();
            t.cycles += s.cycles;
            t.values += s.values;
            t.frames += s.frames;
            t.overruns += s.overruns;
            t.timeouts += s.timeouts;
            t.resends += s.resends;
            t.end_codes += s.end_codes;
            t.other_node_answers += s.other_node_answers;
            online += p->online() ? 1u : 0u;
            polled += p->running() ? 1u : 0u;
        }
        const auto now = Clock::now();
        const double seconds = std::chrono::duration<double>(now - last_report_).count();
        auto m = mqtt_ ? mqtt_->stats() : MqttStats{};
        // The format's own session (Sparkplug) carries its births and data: they count as
        // published like JSON messages do; its connects are counted apart.
        const auto s = session_ ? session_->stats() : MqttStats{};
        m.published += s.published;
        m.dropped += s.dropped;
        nlohmann::json j{
            {"instance", config_.instance},
            {"ts", epoch_ms()},
            {"plcs_polled", polled},
            {"plcs_online", online},
            {"values_per_s", static_cast<double>(t.values - last_totals_.values) / seconds},
            {"values", t.values},
            {"cycles", t.cycles},
            {"frames", t.frames},
            {"overruns", t.overruns},
            {"timeouts", t.timeouts},
            {"resends", t.resends},
            {"end_codes", t.end_codes},
            {"other_node_answers", t.other_node_answers},
            {"published", m.published},
            {"dropped", m.dropped},
            {"connects", m.connects},
            {"commands_dropped", dropped_commands_},
            {"commands_rejected", format_->rejected_commands()},
            {"commands_failed", failed_commands_}};
        if (session_) j["session_connects"] = s.connects;
        last_totals_ = t;
        last_report_ = now;
        spdlog::info("stats {}", j.dump());
        publish({fmt::format("{}/$bridge/{}/stats", config_.mqtt.topic_prefix, config_.instance),
                 j.dump(), 0, false});
        report();
    });
}

}  // namespace fins::bridge
