// The Sparkplug B payload format (docs/bridge.md "Sparkplug B"): the PayloadFormat seam
// (bridge/payload.hpp) over the Edge Node state machine (edge_node.hpp).
//
// This instance is the Edge Node `spBv1.0/{group_id}/.../{instance}`, each PLC a Device named
// after it, each tag a metric "{group}/{tag}" with an alias and the datatype of its tag type.
//   session_will()         the NDEATH for the next CONNECT (bdSeq + 1): the Will of the
//                          Sparkplug session, a connection of its own (QoS 1, not retained);
//   connected()            NBIRTH and the DBIRTH of every PLC this instance publishes;
//   status()               a PLC going offline: DDEATH; coming online: its DBIRTH waits for
//                          values;
//   values()               the first values of every group of a PLC (after start, or after it
//                          was offline): its DBIRTH, carrying them; then DDATA (the changed
//                          metrics; a failed read is null + Quality BAD);
//   parse()                NCMD "Node Control/Rebirth" = true -> NodeRebirth; DCMD -> a write
//                          command (one metric per DCMD), into the same write path as JSON
//                          writes; anything else addressed to this Edge Node -> Rejected;
//   released()             a PLC now owned by another instance: DDEATH.
// Sparkplug has no write response: the read-back value is published as DDATA, a refused or
// failed command is logged and counted (rejected(), rejected_commands()), never executed.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bridge/config.hpp"
#include "bridge/payload.hpp"
#include "bridge/sparkplug/edge_node.hpp"

namespace fins::bridge::sparkplug {

// A tag's value as a Sparkplug metric value (numbers as the PLC words hold them).
MetricValue to_metric_value(TagType t, const TagValue& v);
DataType datatype_of(TagType t) noexcept;

class SparkplugPayload final : public PayloadFormat {
  public:
    SparkplugPayload(const BridgeConfig& config, std::string group_id);

    [[nodiscard]] std::vector<std::string> subscriptions() const override;
    // online: the retained JSON status `{prefix}/$bridge/{instance}/status`; offline: the same
    // for the bridge connection's Will (membership, cluster_ownership.hpp). The Sparkplug
    // session's Will is will().
    [[nodiscard]] bridge::Message bridge_status(bool online) const override;
    void connected(const Sink& out) override;
    void values(const GroupSample& sample, const Sink& out) override;
    void status(const PlcStatus& status, const Sink& out) override;
    void write_response(const Plc& plc, const WriteResponse& r, const Sink& out) override;
    std::optional<ParsedCommand> parse(std::string_view topic, std::string_view payload,
                                       bool retained) override;

    // The Edge Node session is a connection of its own: its Will is the NDEATH.
    [[nodiscard]] bool own_session() const override { return true; }
    // The NDEATH Will for the session's next CONNECT (bdSeq + 1), asked for by the MQTT
    // client on the bridge's thread before it connects. Until
    // the births that follow the CONNECT nothing else is published (DDATA before NBIRTH
    // would make host applications ask for a rebirth).
    bridge::Message session_will() override;
    // The NDEATH published before a clean disconnect (the Will's bdSeq).
    [[nodiscard]] bridge::Message session_goodbye() const override;
    // The PLC is now another instance's: DDEATH.
    void released(const Plc& plc, const Sink& out) override;

    // Logs and counts a command that is not executed.
    void rejected(std::string_view topic, std::string_view reason) override;
    [[nodiscard]] std::uint64_t rejected_commands() const override { return rejected_; }
    [[nodiscard]] const EdgeNode& node() const noexcept { return node_; }

  private:
    struct Device {
        // metric index -> (group index, tag index); and the tag's name for writes
        std::vector<std::pair<std::size_t, std::size_t>> tags;
        std::vector<std::size_t> group_base;  // first metric index of each group
        const Plc* plc = nullptr;
        // The groups with values since the device came online: its DBIRTH waits for all.
        std::vector<bool> seen;
    };
    void emit(std::vector<sparkplug::Message>& msgs, const Sink& out);

    std::string prefix_;
    std::string instance_;
    EdgeNode node_;
    std::map<std::string, Device, std::less<>> devices_;
    std::vector<sparkplug::Message> scratch_;
    std::vector<MetricUpdate> updates_;
    std::uint64_t next_id_ = 0;
    std::uint64_t rejected_ = 0;
    bool awaiting_birth_ = true;
};

}  // namespace fins::bridge::sparkplug
