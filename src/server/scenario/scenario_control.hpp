// What the control channel asks of a CPU Unit's running scenario (`finsd ctl scenario
// ...`, control_scenario.hpp). ScenarioRunner implements it on the server's io_context;
// every call comes from that same thread.
#pragma once

#include <cstdint>
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
};

class ScenarioControl {
  public:
    virtual ~ScenarioControl() = default;
    [[nodiscard]] virtual ScenarioRunStatus run_status() const = 0;
    virtual void pause() = 0;
    virtual void resume() = 0;
    // Runs `seconds` of scenario time now (virtual or real time); returns the ticks run.
    virtual std::uint64_t advance(double seconds) = 0;
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
