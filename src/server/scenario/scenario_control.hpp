// What the control channel asks of a CPU Unit's running scenario (`finsd ctl scenario
// ...`, control_scenario.hpp). ScenarioRunner implements it on the server's io_context;
// every call comes from that same thread.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include <tl/expected.hpp>

#include "scenario/scenario.hpp"

namespace fins::server {

// The largest `advance`: a week of scenario time in one request.
inline constexpr double max_advance_seconds = 7 * 24 * 3600.0;

struct ScenarioRunStatus {
    scenario::Status status;
    bool paused = false;
    bool virtual_time = false;
    double time_scale = 1.0;
    double tick_s = 0.1;
    std::uint64_t seed = 0;
    std::uint64_t reloads = 0;
    std::string source;  // the file it was loaded from
    // Real time falling behind: ticks the timer dropped because they could not be
    // computed in time (scenario time lags real time by late_ticks x tick_s).
    std::uint64_t late_ticks = 0;
    double behind_s = 0;
    // An advance running in slices: its ticks done and due.
    bool advancing = false;
    std::uint64_t advance_done = 0;
    std::uint64_t advance_ticks = 0;
};

// What an advance answers: the ticks it ran and the scenario time after them.
struct AdvanceAnswer {
    std::uint64_t ticks = 0;
    double time_s = 0;
};
using AdvanceDone = std::function<void(tl::expected<AdvanceAnswer, std::string>)>;

class ScenarioControl {
  public:
    virtual ~ScenarioControl() = default;
    [[nodiscard]] virtual ScenarioRunStatus run_status() const = 0;
    virtual void pause() = 0;
    virtual void resume() = 0;
    // Runs `seconds` of scenario time now (virtual or real time); returns the ticks run.
    virtual std::uint64_t advance(double seconds) = 0;
    // advance() that may run in slices, serving other work between them: `done` is
    // called once, when the ticks have run (or why none ran). This default runs them
    // in one piece.
    virtual void advance_async(double seconds, AdvanceDone done) {
        const auto ticks = advance(seconds);
        done(AdvanceAnswer{ticks, run_status().status.time_s});
    }
    // Why pause, resume, advance, trigger and reload are refused now (an advance still
    // running in slices), or "" when they are not.
    [[nodiscard]] virtual std::string busy() const { return {}; }
    virtual bool trigger(std::string_view event) = 0;
    // Loads the scenario again from its file; on any error the running one stays and
    // the error says why.
    virtual tl::expected<void, std::string> reload() = 0;
    // The running scenario as its file states it (tags with their types, events): read by
    // finsd's page (GET /api/scenario); null when the implementation keeps none. Valid
    // until the next reload().
    [[nodiscard]] virtual const scenario::ScenarioDef* definition() const { return nullptr; }
};

}  // namespace fins::server
