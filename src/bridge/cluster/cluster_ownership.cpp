#include "bridge/cluster/cluster_ownership.hpp"

#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

namespace fins::bridge::cluster {

ClusterOwnership::ClusterOwnership(std::string instance, std::string topic_prefix)
    : prefix_(std::move(topic_prefix)),
      filter_(cluster::status_filter(prefix_)),
      membership_(std::move(instance)) {}

bool ClusterOwnership::on_message(std::string_view topic, std::string_view payload) {
    const auto instance = status_topic_instance(prefix_, topic);
    if (!instance) return false;
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
