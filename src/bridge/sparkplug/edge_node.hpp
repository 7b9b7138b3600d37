// The Sparkplug B Edge Node (Sparkplug 3.0 chapters 4 "Topics", 5 "Operational Behavior",
// 6 "Payloads"): one fins-bridge instance is one Edge Node, each PLC it owns is one Device.
// Pure: no sockets, no clock (the caller hands in ms since the epoch); it turns events into
// messages to publish and incoming NCMD/DCMD payloads into commands.
//
// The session, as the specification orders it:
//   next_will()        before every MQTT CONNECT: the NDEATH Will (QoS 1, not retained) with
//                      the connection's bdSeq (0, 1, ... 255, 0: one step per CONNECT);
//   subscriptions()    after CONNACK, before any birth: NCMD and DCMD/+ at QoS 1;
//   birth()            NBIRTH (seq 0, bdSeq = the Will's, "Node Control/Rebirth" = false) then
//                      a DBIRTH per attached device, in one go;
//   data()             DDATA with aliases only (seq + 1 each, 255 -> 0);
//   attach()/detach()  a device gained or lost later (cluster ownership): DBIRTH / DDEATH;
//   on_command()       NCMD "Node Control/Rebirth" = true -> Rebirth (call birth() again);
//                      DCMD -> one DeviceWrite per metric, for the bridge's write path;
//   death()            the NDEATH to publish before an intentional disconnect.
// Every NBIRTH, DBIRTH, NDATA, DDATA and DDEATH is QoS 0, not retained, with a timestamp; only
// the Will is QoS 1. Nothing is published for a device before the NBIRTH of the session.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "bridge/sparkplug/metric.hpp"

namespace fins::bridge::sparkplug {

inline constexpr std::string_view namespace_v1 = "spBv1.0";
inline constexpr std::string_view rebirth_metric = "Node Control/Rebirth";
inline constexpr std::string_view bdseq_metric = "bdSeq";

// One message for the MQTT client.
struct Message {
    std::string topic;
    std::string payload;  // the serialised protobuf
    int qos = 0;
    bool retain = false;
};

// One metric of a device: a PLC tag, named "{group}/{tag}" (Sparkplug's folder separator).
struct MetricDef {
    std::string name;
    DataType datatype = DataType::Unknown;
    bool writable = false;
};

// A new value (or a failed read: monostate) of the metric at `index` in the device's list.
struct MetricUpdate {
    std::size_t index = 0;
    MetricValue value;
    std::uint64_t timestamp_ms = 0;  // when the PLC's answer arrived
};

// Commands from the host application.
struct Rebirth {};
struct DeviceWrite {
    std::string device;
    std::size_t index = 0;  // into the device's metric list
    std::string metric;     // its name
    MetricValue value;      // converted to the metric's datatype
};
struct CommandError {
    std::string reason;  // for the log and the rejected-command counter
};
using Command = std::variant<Rebirth, DeviceWrite, CommandError>;

class EdgeNode {
  public:
    // group_id and edge_node_id: non-empty, no '/', '+' or '#' (chapter 4); checked by the
    // config, asserted here.
    EdgeNode(std::string group_id, std::string edge_node_id);

    const std::string& group_id() const noexcept { return group_id_; }
    const std::string& edge_node_id() const noexcept { return edge_node_id_; }

    // The NDEATH Will for the next MQTT CONNECT; advances bdSeq (the first call gives 0).
    Message next_will(std::uint64_t now_ms);
    std::uint64_t bd_seq() const noexcept { return bd_seq_; }

    // Topic filters to subscribe to (QoS 1) before birth().
    std::vector<std::string> subscriptions() const;

    // Registers a device's metrics (once per PLC; the list does not change afterwards). The
    // device is detached until attach().
    void define_device(const std::string& name, std::vector<MetricDef> metrics);

    // The whole birth sequence into out: NBIRTH then the DBIRTH of every attached device (with
    // its last known values). Also the answer to a Rebirth.
    void birth(std::uint64_t now_ms, std::vector<Message>& out);
    bool born() const noexcept { return born_; }
    // The MQTT connection is gone: nothing more is published until the next birth().
    void connection_lost() noexcept { born_ = false; }

    // Ownership: a device starts or stops being published by this node. attach() publishes its
    // DBIRTH at once when the node is born; detach() its DDEATH.
    void attach(const std::string& device, std::uint64_t now_ms, std::vector<Message>& out);
    void detach(const std::string& device, std::uint64_t now_ms, std::vector<Message>& out);
    bool attached(const std::string& device) const;

    // New values of a device: one DDATA (nothing if not born, not attached, or updates is
    // empty). The values are also kept for the next DBIRTH, also while the device is detached:
    // attach() after data() births it with them.
    void data(const std::string& device, std::span<const MetricUpdate> updates,
              std::uint64_t now_ms, std::vector<Message>& out);

    // An incoming NCMD or DCMD (topic and payload as received). A DCMD may set several
    // metrics: each becomes one DeviceWrite in out; a bad one becomes a CommandError.
    void on_command(std::string_view topic, std::string_view payload,
                    std::vector<Command>& out) const;

    // The NDEATH to publish before an intentional disconnect (same bdSeq as the Will).
    Message death(std::uint64_t now_ms) const;

    // The next seq (for tests): 0 after birth()'s NBIRTH.
    std::uint8_t next_seq() const noexcept { return seq_; }

    std::string topic(std::string_view verb, std::string_view device = {}) const;

  private:
    struct Device {
        std::uint64_t alias_base = 0;
        std::vector<MetricDef> metrics;
        std::vector<MetricValue> last;
        std::vector<std::uint64_t> last_ts;
        bool attached = false;
    };

    std::uint64_t take_seq() noexcept;
    void device_birth(const std::string& name, Device& d, std::uint64_t now_ms,
                      std::vector<Message>& out);
    void finish(std::string topic, int qos, std::vector<Message>& out);
    const Device* find(std::string_view name) const;

    std::string group_id_;
    std::string edge_node_id_;
    std::map<std::string, Device, std::less<>> devices_;
    std::uint64_t next_alias_base_ = 1;
    std::uint64_t bd_seq_ = 0;
    bool have_will_ = false;
    bool born_ = false;
    std::uint8_t seq_ = 0;
    PbPayload scratch_;  // reused for every message: its repeated fields keep their capacity
};

// Splits "spBv1.0/{group}/{verb}/{node}[/{device}]"; nullopt when it is not one.
struct TopicParts {
    std::string_view group_id, verb, edge_node_id, device_id;
};
std::optional<TopicParts> parse_topic(std::string_view topic);

}  // namespace fins::bridge::sparkplug
