// Which fins-bridge instances are alive, and which of them owns each PLC.
//
// Membership is read from the broker, the one place every instance already talks to: each
// instance publishes `{prefix}/$bridge/{instance}/status` retained, {"state":"online",...}
// after it connects, and registers {"state":"offline",...} as its MQTT Will, so the broker
// itself announces a crash (kill -9, power loss, network loss) once the instance's keep-alive
// has run out (1.5 x keepalive, MQTT 3.1.1 3.1.2.10). Every instance subscribes to
// `{prefix}/$bridge/+/status`, and the owner of a PLC is the rendezvous-hash winner among the
// members that are online (rendezvous.hpp).
//
// An instance claims nothing until it is "synced": it sees its own "online" come back from the
// broker. The broker sends the retained statuses of the others on subscription, before that
// echo, so by then the member list is the broker's. On a single broker, status changes and
// write commands reach every instance in the one order the broker processed them, so the old
// and the new owner of a PLC agree on which writes came before the change and which after:
// a write is executed by at most one instance. docs/bridge.md "Several instances" says what
// holds where this does not (broker clusters, partitions).
//
// Pure: the MQTT client hands messages in; on_status() says when ownership may have changed,
// the caller then asks owns() for each PLC and starts or stops polling.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace fins::bridge::cluster {

// Instances known at most (self not counted): the statuses of further names are ignored,
// counted (refused()) and logged.
inline constexpr std::size_t max_members = 256;

class Membership {
  public:
    explicit Membership(std::string self);

    const std::string& self() const noexcept { return self_; }

    // A message on `{prefix}/$bridge/{instance}/status` (an empty payload: the retained status
    // was cleared, the instance is gone). Returns true when the set of live members, or whether
    // this instance is synced, changed: ownership must be re-evaluated.
    bool on_status(std::string_view instance, std::string_view payload);

    // The connection to the broker is gone: own nothing until synced again (the others will
    // take over once the broker publishes this instance's Will). Returns true if that changed
    // anything.
    bool connection_lost();

    bool synced() const noexcept { return synced_; }
    // Live members, sorted by name (self included once synced).
    const std::vector<std::string>& members() const noexcept { return live_; }

    // Whether this instance polls plc and executes its writes.
    bool owns(std::string_view plc) const noexcept;
    // Whether this instance owns plc among the live members plus itself (before it is
    // synced: the owner it will be).
    bool owns_once_joined(std::string_view plc) const;
    // The live owner of plc (empty when nobody is live).
    std::string_view owner(std::string_view plc) const noexcept;

    // Membership changes seen (joins + deaths), for the bridge's counters.
    std::uint64_t changes() const noexcept { return changes_; }
    // "online" statuses of new names ignored at the max_members bound.
    std::uint64_t refused() const noexcept { return refused_; }
    // Instances known online (self included once it said so).
    std::size_t known() const noexcept { return online_.size(); }

  private:
    void rebuild();

    std::string self_;
    std::set<std::string, std::less<>> online_;  // the instances whose last status is online
    std::vector<std::string> live_;
    bool synced_ = false;
    std::uint64_t changes_ = 0;
    std::uint64_t refused_ = 0;
};

// "{prefix}/$bridge/{instance}/status" -> instance; nullopt for any other topic.
std::optional<std::string_view> status_topic_instance(std::string_view prefix,
                                                      std::string_view topic);
std::string status_topic(std::string_view prefix, std::string_view instance);
// The filter that matches every instance's status.
std::string status_filter(std::string_view prefix);

// The MQTT keepalive (s) that makes the broker publish a silent instance's Will within
// failover_s: MQTT 3.1.1 3.1.2.10 has the server act after 1.5 x keepalive without a packet
// (plus up to 1 s of rounding). At least 5 s (libmosquitto's minimum): failover_s below 9
// cannot be met and gives 5. A broker that checks less often adds its period: mosquitto
// 2.0.11 looks every 6 s (src/keepalive.c), docs/bridge.md "Several instances".
int keepalive_for_failover(int failover_s) noexcept;

}  // namespace fins::bridge::cluster
