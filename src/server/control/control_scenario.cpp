// The control channel's scenario verb (contract in control_scenario.hpp).
#include "server/control/control_scenario.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "server/control/control_requests.hpp"
#include "server/scenario/scenario_control.hpp"

namespace fins::server {

namespace {

using Json = nlohmann::json;

Json status_json(const ScenarioRunStatus& run) {
    Json events = Json::array();
    for (const auto& e : run.status.events) {
        Json event{{"name", e.name}, {"fault", e.fault}, {"active", e.active}};
        if (e.next_start_s >= 0) event["next_start_s"] = e.next_start_s;
        events.push_back(std::move(event));
    }
    Json status{{"time_s", run.status.time_s},
                {"ticks", run.status.ticks},
                {"tags", run.status.tags},
                {"writes", run.status.writes},
                {"skipped_writes", run.status.skipped_writes},
                {"paused", run.paused},
                {"time", run.virtual_time ? "virtual" : "real"},
                {"time_scale", run.time_scale},
                {"tick_ms", std::llround(run.tick_s * 1000)},
                {"seed", run.seed},
                {"reloads", run.reloads},
                {"source", run.source},
                {"late_ticks", run.late_ticks},
                {"behind_s", run.behind_s},
                {"events", std::move(events)}};
    if (run.advancing)
        status["advancing"] = {{"ticks_done", run.advance_done}, {"ticks", run.advance_ticks}};
    return status;
}

std::string action_of(const Json& j) {
    const auto it = j.find("action");
    return it != j.end() && it->is_string() ? it->get<std::string>() : "";
}

Json no_scenario() {
    return control_error(
        "this CPU Unit runs no scenario (finsd --scenario FILE, or a [scenario] table)");
}

// The seconds of an advance request, or the error to answer.
tl::expected<double, Json> advance_seconds(const Json& j) {
    const auto s = j.find("seconds");
    if (s == j.end() || !s->is_number() || !(s->get<double>() > 0) ||
        s->get<double>() > max_advance_seconds)
        return tl::unexpected(control_error(fmt::format(
            "\"seconds\" must be a number above 0 and at most {}", max_advance_seconds)));
    return s->get<double>();
}

Json advance_json(const AdvanceAnswer& a) {
    return Json{{"ok", true}, {"ticks", a.ticks}, {"time_s", a.time_s}};
}

}  // namespace

void handle_scenario_request(ScenarioControl* scenario, const Json& j,
                             const std::function<void(Json)>& reply) {
    if (scenario == nullptr) return reply(no_scenario());
    if (action_of(j) != "advance") return reply(handle_scenario_request(scenario, j));
    if (const auto why = scenario->busy(); !why.empty()) return reply(control_error(why));
    const auto seconds = advance_seconds(j);
    if (!seconds) return reply(seconds.error());
    scenario->advance_async(*seconds, [reply](tl::expected<AdvanceAnswer, std::string> a) {
        reply(a ? advance_json(*a) : control_error(a.error()));
    });
}

Json handle_scenario_request(ScenarioControl* scenario, const Json& j) {
    if (scenario == nullptr) return no_scenario();
    const std::string action = action_of(j);
    if (action == "status")
        return Json{{"ok", true}, {"scenario", status_json(scenario->run_status())}};
    // While an advance runs in slices, the verbs that change the run wait for its answer.
    if (const auto why = scenario->busy();
        !why.empty() && (action == "pause" || action == "resume" || action == "advance" ||
                         action == "trigger" || action == "reload"))
        return control_error(why);
    if (action == "pause") {
        scenario->pause();
    } else if (action == "resume") {
        scenario->resume();
    } else if (action == "advance") {
        const auto seconds = advance_seconds(j);
        if (!seconds) return seconds.error();
        const auto ticks = scenario->advance(*seconds);
        return advance_json({ticks, scenario->run_status().status.time_s});
    } else if (action == "trigger") {
        const auto e = j.find("event");
        if (e == j.end() || !e->is_string())
            return control_error("\"event\" must be an event name");
        if (!scenario->trigger(e->get<std::string>()))
            return control_error(
                fmt::format("no event named \"{}\" (finsd ctl scenario status "
                            "lists them)",
                            e->get<std::string>()));
    } else if (action == "reload") {
        if (auto r = scenario->reload(); !r)
            return control_error("reload refused, the running scenario stays: " + r.error());
    } else {
        return control_error(
            "\"action\" must be status, pause, resume, advance, trigger or reload");
    }
    return Json{{"ok", true}};
}

}  // namespace fins::server
