// `finsd ctl scenario ...` (contract in ctl_scenario.hpp).
#include "finsd/ctl_scenario.hpp"

#include <memory>
#include <string>

namespace fins::finsd {

void add_scenario_verbs(CLI::App& app, nlohmann::json& request) {
    auto* c = app.add_subcommand("scenario", "The CPU Unit's scenario (docs/scenarios.md)");
    c->require_subcommand(1);
    // Kept alive by the callbacks: CLI11 fills them while parsing.
    auto seconds = std::make_shared<double>(0.0);
    auto event = std::make_shared<std::string>();
    const auto simple = [&](const char* name, const char* help) {
        c->add_subcommand(name, help)->callback([&request, name] {
            request = {{"cmd", "scenario"}, {"action", name}};
        });
    };
    simple("status", "Time, ticks, writes and events as JSON");
    simple("pause", "Stop scenario time (tags keep their values)");
    simple("resume", "Let scenario time go on");
    simple("reload", "Read the scenario file again (a bad file keeps the running one)");
    auto* advance = c->add_subcommand("advance", "Run SECONDS of scenario time now");
    advance->add_option("seconds", *seconds, "Scenario seconds, e.g. 2.5")->required();
    advance->callback([&request, seconds] {
        request = {{"cmd", "scenario"}, {"action", "advance"}, {"seconds", *seconds}};
    });
    auto* trigger = c->add_subcommand("trigger", "Start an event now (by its name)");
    trigger->add_option("event", *event, "The event's name (event-N when it has none)")->required();
    trigger->callback([&request, event] {
        request = {{"cmd", "scenario"}, {"action", "trigger"}, {"event", *event}};
    });
    // `finsd ctl advance S`: an alias of `scenario advance S`, the same request.
    auto* alias = app.add_subcommand("advance", "Alias of `scenario advance SECONDS`");
    alias->add_option("seconds", *seconds, "Scenario seconds, e.g. 2.5")->required();
    alias->callback([&request, seconds] {
        request = {{"cmd", "scenario"}, {"action", "advance"}, {"seconds", *seconds}};
    });
}

}  // namespace fins::finsd
