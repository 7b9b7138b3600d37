// GET /api/scenario's object (contract in api_scenario.hpp).
#include "web/api_scenario.hpp"

#include <string>

#include <fmt/core.h>

#include "scenario/definition.hpp"
#include "server/control/control_scenario.hpp"
#include "server/scenario/scenario_control.hpp"

namespace fins::web {

namespace {

using Json = nlohmann::json;

std::string type_name(scenario::ValueType type) {
    return std::string(scenario::value_type_name(type));
}

}  // namespace

Json scenario_object(const server::ControlTarget& target) {
    if (target.scenario == nullptr) return nullptr;
    Json status = server::handle_scenario_request(
        target.scenario, Json{{"cmd", "scenario"}, {"action", "status"}})["scenario"];
    Json answer{{"status", status}};
    if (!target.name.empty()) answer["plc"] = target.name;
    const auto* def = target.scenario->definition();
    Json tags = Json::array();
    Json inputs = Json::array();
    Json events = Json::array();
    const Json& running = status["events"];
    if (def != nullptr) {
        for (std::size_t i = 0; i < def->tags.size() && i < max_listed_tags; ++i) {
            const auto& t = def->tags[i];
            tags.push_back({{"address", t.address.text},
                            {"type", type_name(t.type)},
                            {"words", scenario::value_words(t.type)},
                            {"kind", std::string(scenario::signal_kind_name(t.kind))}});
        }
        for (const auto& in : def->inputs)
            inputs.push_back({{"address", in.address.text}, {"type", type_name(in.type)}});
        for (std::size_t i = 0; i < def->events.size(); ++i) {
            const auto& e = def->events[i];
            Json event{{"name", e.name.empty() ? fmt::format("event-{}", i + 1) : e.name},
                       {"fault", std::string(scenario::fault_kind_name(e.fault))},
                       {"duration_s", e.duration_s}};
            if (!e.address.text.empty()) event["address"] = e.address.text;
            if (e.at_s) event["at_s"] = *e.at_s;
            if (e.every_s) event["every_s"] = *e.every_s;
            // The run's state of the same event (the status lists them in file order).
            if (running.is_array() && i < running.size()) {
                event["active"] = running[i].value("active", false);
                if (running[i].contains("next_start_s"))
                    event["next_start_s"] = running[i]["next_start_s"];
            }
            events.push_back(std::move(event));
        }
    } else if (running.is_array()) {
        events = running;
    }
    answer["tags"] = std::move(tags);
    answer["tags_total"] = def != nullptr ? def->tags.size() : std::size_t{0};
    answer["inputs"] = std::move(inputs);
    answer["events"] = std::move(events);
    return answer;
}

}  // namespace fins::web
