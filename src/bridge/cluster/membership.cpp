#include "bridge/cluster/membership.hpp"

#include <algorithm>
#include <utility>

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "bridge/cluster/rendezvous.hpp"

namespace fins::bridge::cluster {

Membership::Membership(std::string self) : self_(std::move(self)) {}

bool Membership::on_status(std::string_view instance, std::string_view payload) {
    // No status topic names the empty instance (status_topic_instance()): not a member.
    if (instance.empty()) return false;
    bool online = false;
    if (!payload.empty()) {
        // Anything but a JSON object with "state":"online" counts as not alive: a member is
        // trusted only when it says so.
        const auto j = nlohmann::json::parse(payload, nullptr, false);
        if (j.is_object()) {
            const auto it = j.find("state");
            online =
                it != j.end() && it->is_string() && it->get_ref<const std::string&>() == "online";
        }
    }
    const bool was_synced = synced_;
    if (instance == self_) {
        // Our own "online" coming back means every retained status before it has been seen.
        // Our own "offline" is a Will of an earlier connection: the broker thought us dead, and
        // until our new "online" comes back we may have been replaced.
        synced_ = online;
    }
    // Only the instances that say they are online are kept: a name that goes offline is
    // forgotten, and beyond max_members names the others are refused (any client of the
    // broker can publish a status, so the table is bounded).
    const auto it = online_.find(instance);
    const bool known = it != online_.end();
    if (online && !known) {
        const std::size_t others = online_.size() - online_.count(self_);
        if (others >= max_members && instance != self_) {
            if (refused_++ % 1024 == 0)
                spdlog::warn(
                    "cluster: status of '{}' ignored: {} members known already (the "
                    "bound), {} ignored so far",
                    instance, online_.size(), refused_);
            if (was_synced == synced_) return false;
        } else {
            online_.emplace(instance);
        }
    } else if (!online && known) {
        online_.erase(it);
    } else if (was_synced == synced_) {
        return false;
    }
    const auto before = live_;
    rebuild();
    const bool changed = before != live_ || was_synced != synced_;
    if (changed) ++changes_;
    return changed;
}

bool Membership::connection_lost() {
    if (!synced_) return false;
    synced_ = false;
    rebuild();
    ++changes_;
    return true;
}

void Membership::rebuild() {
    live_.clear();
    for (const auto& name : online_) {
        if (name == self_ && !synced_) continue;
        live_.push_back(name);
    }
    // std::set iterates in order: live_ is sorted already.
}

bool Membership::owns(std::string_view plc) const noexcept {
    if (!synced_) return false;
    const auto i = rendezvous_owner(live_, plc);
    return i < live_.size() && live_[i] == self_;
}

bool Membership::owns_once_joined(std::string_view plc) const {
    if (synced_) return owns(plc);
    auto with_self = live_;
    if (std::find(with_self.begin(), with_self.end(), self_) == with_self.end())
        with_self.push_back(self_);
    const auto i = rendezvous_owner(with_self, plc);
    return i < with_self.size() && with_self[i] == self_;
}

std::string_view Membership::owner(std::string_view plc) const noexcept {
    const auto i = rendezvous_owner(live_, plc);
    return i < live_.size() ? std::string_view(live_[i]) : std::string_view{};
}

std::optional<std::string_view> status_topic_instance(std::string_view prefix,
                                                      std::string_view topic) {
    constexpr std::string_view middle = "/$bridge/";
    constexpr std::string_view tail = "/status";
    if (topic.size() <= prefix.size() + middle.size() + tail.size()) return std::nullopt;
    if (topic.substr(0, prefix.size()) != prefix) return std::nullopt;
    topic.remove_prefix(prefix.size());
    if (topic.substr(0, middle.size()) != middle) return std::nullopt;
    topic.remove_prefix(middle.size());
    if (topic.substr(topic.size() - tail.size()) != tail) return std::nullopt;
    topic.remove_suffix(tail.size());
    if (topic.empty() || topic.find('/') != std::string_view::npos) return std::nullopt;
    return topic;
}

std::string status_topic(std::string_view prefix, std::string_view instance) {
    std::string t(prefix);
    t.append("/$bridge/").append(instance).append("/status");
    return t;
}

std::string status_filter(std::string_view prefix) {
    std::string t(prefix);
    t.append("/$bridge/+/status");
    return t;
}

int keepalive_for_failover(int failover_s) noexcept {
    // Will after 1.5 x keepalive, plus up to 1 s of the broker's whole-second clock:
    // keepalive = (failover_s - 1) / 1.5, rounded down.
    const int k = (failover_s - 1) * 2 / 3;
    return std::max(k, 5);
}

}  // namespace fins::bridge::cluster
