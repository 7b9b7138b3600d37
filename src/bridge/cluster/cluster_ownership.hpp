// The multi-instance Ownership (bridge/ownership.hpp): the PLCs this instance polls and
// writes are those rendezvous hashing gives it among the live members (membership.hpp).
//
// The bridge's MQTT connection feeds it: every message on status_filter() goes to
// on_status_message(), a lost connection to connection_lost(). Whenever the owner of some PLC
// may have changed it calls the Ownership change handler; the bridge then starts polling what
// it gained and stops what it lost (Bridge::reconcile()).
//
// A cluster is the instances of one payload kind: a status's "payload" ("sparkplug"; absent:
// "json") is part of a member's identity. An instance of the other kind on the same prefix is
// no member (logged): a JSON and a Sparkplug instance would otherwise split the PLCs between
// them, and each PLC's data would appear in only one of the two forms.
#pragma once

#include <string>
#include <string_view>

#include "bridge/cluster/membership.hpp"
#include "bridge/ownership.hpp"

namespace fins::bridge::cluster {

class ClusterOwnership final : public Ownership {
  public:
    // payload_kind: this instance's [bridge] payload ("json" or "sparkplug").
    ClusterOwnership(std::string instance, std::string topic_prefix,
                     std::string payload_kind = "json");

    [[nodiscard]] bool owns(std::string_view plc) const override { return membership_.owns(plc); }
    [[nodiscard]] bool joined() const override { return membership_.synced(); }
    [[nodiscard]] bool owns_once_joined(std::string_view plc) const override {
        return membership_.owns_once_joined(plc);
    }

    // Every instance's retained status (QoS 1).
    [[nodiscard]] std::vector<std::string> subscriptions() const override { return {filter_}; }
    // A message on the bridge's connection; false when it is not a status (not consumed).
    bool on_message(std::string_view topic, std::string_view payload) override;
    void connection_lost() override;

    [[nodiscard]] const Membership& membership() const noexcept { return membership_; }

  private:
    std::string prefix_;
    std::string kind_;
    std::string filter_;
    Membership membership_;
};

}  // namespace fins::bridge::cluster
