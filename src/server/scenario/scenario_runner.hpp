// A CPU Unit's running scenario on the server's io_context (issue 19): its ticks on the
// io_context's ScenarioTicker, the control verbs (ScenarioControl) and the unit faults the network
// side consults (FaultHook). One per CPU Unit; everything runs on the io_context's one thread.
//
// start() computes the tags at time 0 (Scenario::start): memory holds f(0) before the
// first tick, in real and virtual time.
// Real time: ticks every tick_s / time_scale wall-clock seconds, drift-free (each expiry
// is the previous one plus the period, not "now" plus the period). A late timer (a busy
// host) runs the missed ticks, at most max_catch_up at once; beyond that the ticks due
// are dropped and scenario time falls behind rather than stalling the requests: the
// status counts them (late_ticks, behind_s) and the log says so (once a minute at
// most). Scenario time is always ticks * tick_s, so a run is the same whatever the
// host's timing.
// Virtual time: no timer; time moves only by advance() (`finsd ctl scenario advance`).
// advance_async runs the ticks in slices of about advance_slice, posted back to the
// io_context between slices so the FINS requests are served meanwhile; until it answers
// the timer's ticks wait, and every other verb but status is refused (busy()). The
// memory after a sliced advance is the memory after the same ticks in one piece.
// Reload compiles the new file first and swaps only on success; the new scenario goes on
// at the old one's time (Scenario::continue_from); the unit faults the old one had started
// are cleared with it.
// With a ScenarioWorker (finsd's), a real-time tick of an offloadable scenario is handed
// over: begin_tick here, compute on the worker, end_tick here when it comes back (one tick
// in flight at most; the next is due one period later). Every control verb settles a tick
// in flight first, so it sees (and changes) the scenario between ticks.
#pragma once

#include <array>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "scenario/random.hpp"
#include "scenario/scenario.hpp"
#include "server/scenario/fault_hook.hpp"
#include "server/scenario/scenario_control.hpp"
#include "server/scenario/scenario_ticker.hpp"
#include "server/scenario/scenario_worker.hpp"
#include "transport/asio.hpp"

namespace fins::server {

class ScenarioRunner final : public ScenarioControl,
                             public FaultHook,
                             private ScenarioWorker::Job,
                             private ScenarioTicker::Client {
  public:
    using Compiled = tl::expected<std::unique_ptr<scenario::Scenario>, std::string>;
    // Reads and compiles the scenario again (for reload).
    using Reloader = std::function<Compiled()>;

    static constexpr unsigned max_catch_up = 10;
    // A plant's CPU Units tick in this many groups spread over the period (phase_of):
    // each group's ticks are one short burst on the I/O thread, and the thread wakes
    // for ticks only this many times a period, however many units there are.
    static constexpr unsigned phase_groups = 10;
    // The start phase of the plant's `unit`-th CPU Unit.
    [[nodiscard]] static double phase_of(std::size_t unit) noexcept {
        return static_cast<double>(unit % phase_groups) / phase_groups;
    }
    static constexpr std::size_t max_delayed_answers = 1024;
    // An advance_async slice: ticks run back to back for about this long.
    static constexpr std::chrono::milliseconds advance_slice{5};
    // The "falls behind" warning, at most once per this much time.
    static constexpr std::chrono::seconds behind_log_interval{60};

    // `worker` (may be null: every tick on this thread) must outlive the runner.
    ScenarioRunner(asio::io_context& io, std::unique_ptr<scenario::Scenario> scenario,
                   Reloader reload, std::string source, ScenarioWorker* worker = nullptr);
    ~ScenarioRunner() override;
    ScenarioRunner(const ScenarioRunner&) = delete;
    ScenarioRunner& operator=(const ScenarioRunner&) = delete;

    // Real time: the first tick now, then the timer. Virtual: nothing until advance().
    // With `phase` (0-1): the ticks fall on a grid of the period shared by every runner
    // of the process (steady clock), that fraction into each period. A plant gives its
    // units phase_of(i): the units of a group expire at the same instant (one wakeup of
    // the I/O thread for the group), and the groups spread over the period, so no burst
    // of every unit's tick holds the requests waiting on that thread.
    void start(std::optional<double> phase = std::nullopt);
    void stop();
    [[nodiscard]] const scenario::Scenario& scenario() const noexcept { return *scenario_; }
    // Ends a tick in flight on the worker now (waiting for its compute if needed).
    void settle();
    // What the timer's expiry runs, at steady time `now` (tests pass the time in), and
    // when the next tick is due.
    void run_due(std::chrono::steady_clock::time_point now);
    [[nodiscard]] std::chrono::steady_clock::time_point next_due() const noexcept { return next_; }

    // ScenarioControl
    [[nodiscard]] ScenarioRunStatus run_status() const override;
    void pause() override;
    void resume() override;
    std::uint64_t advance(double seconds) override;
    void advance_async(double seconds, AdvanceDone done) override;
    [[nodiscard]] std::string busy() const override;
    bool trigger(std::string_view event) override;
    tl::expected<void, std::string> reload() override;
    [[nodiscard]] const scenario::ScenarioDef* definition() const override {
        return &scenario_->definition();
    }

    // FaultHook
    [[nodiscard]] bool offline() const noexcept override;
    bool silent() noexcept override;
    [[nodiscard]] std::uint16_t area_end_code(const MemoryAddress& address) const noexcept override;
    [[nodiscard]] std::chrono::milliseconds latency() const noexcept override;
    void send_later(Bytes response, Completion completion) override;

  private:
    // ScenarioWorker::Job
    void compute() noexcept override;
    void finish() noexcept override;

    // ScenarioTicker::Client (and ScenarioWorker::Job's prefetch)
    void due() noexcept override;
    void prefetch() const noexcept override;
    // The scenario's virtual_time, offloadable() and prefetch addresses (at start and
    // after a reload).
    void adopt_scenario() noexcept;

    void schedule();
    void flush_delayed();
    // The ticks due at `now` the timer drops: counted, and logged (rate-limited).
    void fall_behind(std::uint64_t ticks, std::chrono::steady_clock::time_point now);
    // Runs a slice of the advance in progress; posts the next, or answers.
    void advance_slice_run();

    // What a tick reads of the runner first, on the object's first lines (the ticker
    // prefetches them a unit ahead): the scenario, the schedule, the flags, and where the
    // scenario's tick starts reading (Scenario::prefetch_addresses).
    std::unique_ptr<scenario::Scenario> scenario_;
    // The io_context's one timer for scenario ticks (ScenarioTicker, a service).
    ScenarioTicker& ticker_;
    ScenarioWorker* worker_ = nullptr;
    std::chrono::steady_clock::duration period_{};
    std::chrono::steady_clock::time_point next_{};
    // The scenario's virtual_time and offloadable(), kept here: a plant's on_tick reads
    // them for every unit every period, and the scenario's own lines are cold then.
    bool virtual_time_ = false;
    bool offloadable_ = false;
    bool in_flight_ = false;  // a tick handed to the worker, not yet ended
    bool running_ = false;
    bool paused_ = false;
    std::array<const void*, scenario::Scenario::prefetch_count> prefetch_{};
    asio::io_context& io_;
    Reloader reload_;
    std::string source_;
    std::uint64_t reloads_ = 0;
    // Draws for the drop fraction: its own generator, so that client traffic never
    // changes the scenario's random numbers (and memory stays deterministic).
    scenario::Random drops_;
    struct Delayed {
        std::chrono::steady_clock::time_point due;
        std::vector<std::uint8_t> frame;
        Completion completion;
    };
    // Falling behind (fall_behind).
    std::uint64_t late_ticks_ = 0;
    std::chrono::steady_clock::time_point next_behind_log_{};
    // The advance running in slices (advance_async).
    bool advancing_ = false;
    std::uint64_t advance_left_ = 0;
    std::uint64_t advance_ticks_ = 0;
    AdvanceDone advance_done_;
    std::deque<Delayed> delayed_;
    asio::steady_timer delay_timer_;
    bool delay_armed_ = false;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fins::server
