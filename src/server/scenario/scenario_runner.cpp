// A CPU Unit's running scenario on the io_context (contract in scenario_runner.hpp).
#include "server/scenario/scenario_runner.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

namespace fins::server {

namespace {

std::chrono::system_clock::time_point host_now() {
    return std::chrono::system_clock::now();
}

}  // namespace

ScenarioRunner::ScenarioRunner(asio::io_context& io, std::unique_ptr<scenario::Scenario> scenario,
                               Reloader reload, std::string source, ScenarioWorker* worker)
    : scenario_(std::move(scenario)),
      ticker_(asio::use_service<ScenarioTicker>(io)),
      worker_(worker),
      io_(io),
      reload_(std::move(reload)),
      source_(std::move(source)),
      drops_(scenario_->definition().seed ^ 0xD809D809D809D809ULL),
      delay_timer_(io) {
    adopt_scenario();
}

void ScenarioRunner::adopt_scenario() noexcept {
    virtual_time_ = scenario_->definition().virtual_time;
    offloadable_ = scenario_->offloadable();
    prefetch_ = scenario_->prefetch_addresses();
}

void ScenarioRunner::prefetch() const noexcept {
    for (const void* p : prefetch_)
        if (p != nullptr) __builtin_prefetch(p);
}

ScenarioRunner::~ScenarioRunner() {
    if (advancing_) {
        advancing_ = false;
        auto done = std::move(advance_done_);
        done(tl::unexpected(std::string("the scenario stopped before the advance ended")));
    }
    settle();
    ticker_.cancel(*this);
    *alive_ = false;
}

void ScenarioRunner::settle() {
    if (!in_flight_) return;
    worker_->settle(*this);
    scenario_->end_tick();
    in_flight_ = false;
}

void ScenarioRunner::compute() noexcept {
    scenario_->compute();
}

void ScenarioRunner::finish() noexcept {
    scenario_->end_tick();
    in_flight_ = false;
    if (running_ && !paused_) schedule();
}

void ScenarioRunner::start(std::optional<double> phase) {
    const auto& def = scenario_->definition();
    period_ = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(def.tick_s / def.time_scale));
    if (period_ <= std::chrono::steady_clock::duration::zero())
        period_ = std::chrono::microseconds(1);
    running_ = true;
    // Memory holds the tags at the scenario's time from the start (f(0), or the time a
    // reload kept: continue_from).
    scenario_->start(host_now());
    if (def.virtual_time || paused_ || advancing_) return;
    if (phase) {
        const auto now = std::chrono::steady_clock::now();
        const auto offset = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            period_ * std::clamp(*phase, 0.0, 1.0));
        // The start of this period on the grid every runner shares, plus the phase.
        next_ = now - now.time_since_epoch() % period_ + offset;
        if (next_ <= now) next_ += period_;
        schedule();
        return;
    }
    next_ = std::chrono::steady_clock::now() + period_;
    schedule();
}

void ScenarioRunner::stop() {
    if (advancing_) {
        advancing_ = false;
        auto done = std::move(advance_done_);
        done(tl::unexpected(std::string("the scenario stopped before the advance ended")));
    }
    settle();
    running_ = false;
    ticker_.cancel(*this);
    delay_timer_.cancel();
    delayed_.clear();
}

void ScenarioRunner::schedule() {
    ticker_.schedule(*this, next_);
}

void ScenarioRunner::due() noexcept {
    run_due(std::chrono::steady_clock::now());
}

void ScenarioRunner::run_due(std::chrono::steady_clock::time_point now) {
    if (!running_ || paused_ || virtual_time_ || advancing_) return;
    if (in_flight_) return;  // its finish() schedules the next
    if (worker_ != nullptr && offloadable_) {
        // One tick per hand-over; a backlog beyond max_catch_up periods is dropped (the
        // grid's phase kept).
        if (next_ > now) {
            schedule();
            return;
        }
        if (now - next_ >= period_ * max_catch_up) {
            const auto missed = (now - next_) / period_;
            fall_behind(static_cast<std::uint64_t>(missed), now);
            next_ += missed * period_;
        }
        scenario_->begin_tick(host_now());
        next_ += period_;
        in_flight_ = true;
        worker_->submit(*this);
        return;
    }
    unsigned ran = 0;
    while (next_ <= now && ran < max_catch_up) {
        scenario_->tick(host_now());
        next_ += period_;
        ++ran;
    }
    // Too far behind: drop the backlog rather than stall every request behind it (the
    // ticks due by now, the grid's phase kept).
    if (next_ <= now) {
        const auto missed = (now - next_) / period_ + 1;
        fall_behind(static_cast<std::uint64_t>(missed), now);
        next_ += missed * period_;
    }
    schedule();
}

void ScenarioRunner::fall_behind(std::uint64_t ticks, std::chrono::steady_clock::time_point now) {
    if (ticks == 0) return;
    late_ticks_ += ticks;
    if (late_ticks_ != ticks && now < next_behind_log_) return;
    next_behind_log_ = now + behind_log_interval;
    const auto& def = scenario_->definition();
    spdlog::warn(
        "finsd: scenario {} falls behind real time: {} ticks dropped so far ({:.3f} s of "
        "scenario time; tick_ms {}, time_scale {}): the host cannot compute its ticks in "
        "time (finsd ctl scenario status: late_ticks, behind_s)",
        source_, late_ticks_, static_cast<double>(late_ticks_) * def.tick_s,
        std::llround(def.tick_s * 1000), def.time_scale);
}

ScenarioRunStatus ScenarioRunner::run_status() const {
    const auto& def = scenario_->definition();
    ScenarioRunStatus s;
    s.status = scenario_->status();
    s.paused = paused_;
    s.virtual_time = def.virtual_time;
    s.time_scale = def.time_scale;
    s.tick_s = def.tick_s;
    s.seed = def.seed;
    s.reloads = reloads_;
    s.source = source_;
    s.late_ticks = late_ticks_;
    s.behind_s = static_cast<double>(late_ticks_) * def.tick_s;
    s.advancing = advancing_;
    s.advance_ticks = advancing_ ? advance_ticks_ : 0;
    s.advance_done = advancing_ ? advance_ticks_ - advance_left_ : 0;
    return s;
}

void ScenarioRunner::pause() {
    settle();
    paused_ = true;
    ticker_.cancel(*this);
}

void ScenarioRunner::resume() {
    if (!paused_) return;
    paused_ = false;
    if (!running_ || scenario_->definition().virtual_time) return;
    // The next tick in the same phase of the period as before the pause (a plant's
    // units stay spread over the period); the paused periods are not run.
    const auto now = std::chrono::steady_clock::now();
    if (next_ <= now) next_ += ((now - next_) / period_ + 1) * period_;
    schedule();
}

std::uint64_t ScenarioRunner::advance(double seconds) {
    settle();
    return scenario_->advance(seconds, host_now());
}

std::string ScenarioRunner::busy() const {
    if (!advancing_) return {};
    return fmt::format("an advance is running ({} of {} ticks done): wait for its answer",
                       advance_ticks_ - advance_left_, advance_ticks_);
}

void ScenarioRunner::advance_async(double seconds, AdvanceDone done) {
    if (advancing_) return done(tl::unexpected(busy()));
    settle();
    scenario_->start(host_now());
    advance_ticks_ = advance_left_ = scenario_->plan_advance(seconds);
    advance_done_ = std::move(done);
    advancing_ = true;
    // The timer's ticks wait for the advance (run_due does nothing meanwhile).
    ticker_.cancel(*this);
    advance_slice_run();
}

void ScenarioRunner::advance_slice_run() {
    if (!advancing_) return;
    using Clock = std::chrono::steady_clock;
    const auto until = Clock::now() + advance_slice;
    // The clock read every few ticks: a small scenario's tick costs less than reading it.
    constexpr std::uint64_t between_reads = 4;
    for (std::uint64_t n = 1; advance_left_ > 0; ++n) {
        scenario_->tick(host_now());
        --advance_left_;
        if (n % between_reads == 0 && Clock::now() >= until) break;
    }
    if (advance_left_ > 0) {
        asio::post(io_, [this, alive = alive_] {
            if (*alive) advance_slice_run();
        });
        return;
    }
    advancing_ = false;
    auto done = std::move(advance_done_);
    advance_done_ = nullptr;
    if (running_ && !paused_ && !virtual_time_) {
        // Real time goes on from now (the advance's wall-clock time is not made up).
        next_ = Clock::now() + period_;
        schedule();
    }
    done(AdvanceAnswer{advance_ticks_, scenario_->time()});
}

bool ScenarioRunner::trigger(std::string_view event) {
    settle();
    return scenario_->trigger(event, host_now());
}

tl::expected<void, std::string> ScenarioRunner::reload() {
    if (!reload_) return tl::unexpected(std::string("this scenario has no file to reload"));
    if (advancing_) return tl::unexpected(busy());
    auto fresh = reload_();
    if (!fresh) return tl::unexpected(fresh.error());
    settle();
    ticker_.cancel(*this);
    // The new scenario goes on at the old one's time, from the memory it left (computed
    // by start(), once the old one is gone with its unit faults).
    (*fresh)->continue_from(*scenario_);
    scenario_ = std::move(*fresh);
    adopt_scenario();
    ++reloads_;
    spdlog::info("finsd: scenario reloaded from {}", source_);
    if (running_) {
        running_ = false;
        start();
    }
    return {};
}

bool ScenarioRunner::offline() const noexcept {
    return scenario_->transport().offline;
}

bool ScenarioRunner::silent() noexcept {
    const auto& f = scenario_->transport();
    if (f.offline) return true;
    return f.drop_fraction > 0 && drops_.uniform() < f.drop_fraction;
}

std::uint16_t ScenarioRunner::area_end_code(const MemoryAddress& address) const noexcept {
    return scenario_->transport().end_code_for(address);
}

std::chrono::milliseconds ScenarioRunner::latency() const noexcept {
    return std::chrono::milliseconds(scenario_->transport().latency_ms);
}

void ScenarioRunner::send_later(Bytes response, Completion completion) {
    // Bounded: beyond max_delayed_answers the oldest goes out now, late but not lost.
    if (delayed_.size() >= max_delayed_answers) {
        auto oldest = std::move(delayed_.front());
        delayed_.pop_front();
        oldest.completion(Bytes(oldest.frame.data(), oldest.frame.size()));
    }
    delayed_.push_back({std::chrono::steady_clock::now() + latency(),
                        std::vector<std::uint8_t>(response.begin(), response.end()),
                        std::move(completion)});
    if (!delay_armed_) flush_delayed();
}

void ScenarioRunner::flush_delayed() {
    const auto now = std::chrono::steady_clock::now();
    while (!delayed_.empty() && delayed_.front().due <= now) {
        auto d = std::move(delayed_.front());
        delayed_.pop_front();
        d.completion(Bytes(d.frame.data(), d.frame.size()));
    }
    delay_armed_ = !delayed_.empty();
    if (!delay_armed_) return;
    delay_timer_.expires_at(delayed_.front().due);
    delay_timer_.async_wait([this, alive = alive_](boost::system::error_code ec) {
        if (!*alive || ec) return;
        flush_delayed();
    });
}

}  // namespace fins::server
