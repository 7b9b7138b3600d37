#include "bridge/cluster/cluster_ownership.hpp"

#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

namespace fins::bridge::cluster {

namespace {

// The payload kind a status announces: its "payload", "json" when it names none (or is no
// JSON object: Membership counts that as not alive anyway).
std::string kind_of(std::string_view payload) {
    const auto j = nlohmann::json::parse(payload, nullptr, false);
    if (!j.is_object()) return "json";
    const auto it = j.find("payload");
    return it != j.end() && it->is_string() ? it->get<std::string>() : std::string("json");
}

}  // namespace

ClusterOwnership::ClusterOwnership(std::string instance, std::string topic_prefix,
                                   std::string payload_kind)
    : prefix_(std::move(topic_prefix)),
      kind_(std::move(payload_kind)),
      filter_(cluster::status_filter(prefix_)),
      membership_(std::move(instance)) {}

bool ClusterOwnership::on_message(std::string_view topic, std::string_view payload) {
    const auto instance = status_topic_instance(prefix_, topic);
    if (!instance) return false;
    if (!payload.empty()) {
        if (const auto kind = kind_of(payload); kind != kind_) {
            // Another payload kind's instance: not a member of this cluster (as if it were gone).
            spdlog::warn(
                "cluster: instance {} publishes payload \"{}\", this one \"{}\": it is not a "
                "member (instances on one topic_prefix must use one payload kind)",
                *instance, kind, kind_);
            payload = {};
        }
    }
    if (membership_.on_status(*instance, payload)) {
        spdlog::info("cluster: members {} ({}synced)", fmt::join(membership_.members(), ", "),
                     membership_.synced() ? "" : "not ");
        changed();
    }
    return true;
}

void ClusterOwnership::connection_lost() {
    if (membership_.connection_lost()) {
        spdlog::warn("cluster: broker connection lost, polling nothing until it is back");
        changed();
    }
}

}  // namespace fins::bridge::cluster
