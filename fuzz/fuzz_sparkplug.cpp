// Sparkplug B commands (issue 25): NCMD/DCMD payloads through EdgeNode::on_command and the
// bridge's whole command path (SparkplugPayload::parse, Bridge's dispatch and write checks),
// with a fixed Edge Node: device "p" (online, attached) with a read-only and writable metrics
// of several datatypes, device "q" (defined, never online).
//
// Input: the first byte picks the topic (low two bits: NCMD, DCMD/p, DCMD/q, DCMD/nope) and
// whether the message is retained (bit 7); the rest is the payload.
//
// Traps (abort) on anything but a clean refusal or a valid command:
// - on_command: a DeviceWrite for a device that is not attached, a metric that is not
//   writable, or a value that is not of its datatype's kind; a Rebirth from a DCMD; a
//   CommandError without a reason;
// - the bridge: handling that throws (its failure boundary counted one), or a message that
//   ends neither as a Rebirth nor as a counted refusal (nothing executes here: the PLC is not
//   polled, so every write is refused by the write path, and counted).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>

#include "bridge/bridge.hpp"
#include "bridge/sparkplug/edge_node.hpp"
#include "bridge/sparkplug/sparkplug_payload.hpp"

namespace fb = fins::bridge;
namespace sp = fins::bridge::sparkplug;
namespace pb = finskit::sparkplug::pb;

namespace {

const char* const config_text = R"([bridge]
payload = "sparkplug"
sparkplug_group = "plant"
[mqtt]
topic_prefix = "plant"
[[plc]]
name = "p"
host = "127.0.0.1"
[[plc.group]]
name = "g"
tags = [ { name = "speed", address = "D100", type = "int16" },
         { name = "level", address = "D101", type = "int16", writable = true },
         { name = "temp", address = "D200", type = "float", writable = true, min = -50, max = 500 },
         { name = "count", address = "D202", type = "uint32", writable = true },
         { name = "big", address = "D204", type = "double", writable = true },
         { name = "run", address = "CIO0.00", type = "bool", writable = true },
         { name = "recipe", address = "D210", type = "string", length = 8, writable = true },
         { name = "code", address = "D220", type = "bcd", writable = true } ]
[[plc]]
name = "q"
host = "127.0.0.1"
[[plc.group]]
name = "g"
tags = [ { name = "x", address = "D0", type = "uint16", writable = true } ]
)";

void trap_unless(bool ok) {
    if (!ok) std::abort();
}

// The value kind a decoded metric of datatype t must have.
bool value_fits(sp::DataType t, const sp::MetricValue& v) {
    switch (t) {
        case pb::Boolean:
            return std::holds_alternative<bool>(v);
        case pb::Int8:
        case pb::Int16:
        case pb::Int32:
        case pb::Int64:
            return std::holds_alternative<std::int64_t>(v);
        case pb::UInt8:
        case pb::UInt16:
        case pb::UInt32:
        case pb::UInt64:
        case pb::DateTime:
            return std::holds_alternative<std::uint64_t>(v);
        case pb::Float:
        case pb::Double:
            return std::holds_alternative<double>(v);
        case pb::String:
        case pb::Text:
        case pb::UUID:
            return std::holds_alternative<std::string>(v);
        default:
            return false;
    }
}

struct World {
    asio::io_context io;
    fb::BridgeConfig config;
    sp::SparkplugPayload* format = nullptr;
    std::unique_ptr<fb::Bridge> bridge;
    sp::EdgeNode node{"plant", "fuzz"};
    std::vector<std::vector<sp::MetricDef>> defs;  // of p, q
    bool rebirth = false;

    World() {
        spdlog::set_level(spdlog::level::off);
        auto c = fb::parse_config(config_text, "fuzz.toml", "fuzz");
        if (!c) std::abort();
        config = std::move(*c);
        auto f = std::make_unique<sp::SparkplugPayload>(config, "plant");
        format = f.get();
        bridge = std::make_unique<fb::Bridge>(io, config, std::move(f),
                                              std::make_unique<fb::SingleInstance>());
        bridge->set_command_hook([this](const fb::ParsedCommand& parsed) {
            rebirth = std::holds_alternative<fb::NodeRebirth>(parsed);
        });
        // p answers a whole cycle: online, its DBIRTH, attached; q never does.
        std::vector<fb::TagSample> tags(config.plcs[0].groups[0].tags.size());
        bridge->status_changed({&config.plcs[0], true, "", 1});
        bridge->group_done({&config.plcs[0], &config.plcs[0].groups[0], tags, 2, true});
        if (!format->node().attached("p") || format->node().attached("q")) std::abort();

        // The same devices on a bare Edge Node for on_command.
        for (const auto& plc : config.plcs) {
            std::vector<sp::MetricDef> d;
            for (const auto& g : plc.groups)
                for (const auto& t : g.tags)
                    d.push_back({g.name + "/" + t.name, sp::datatype_of(t.type), t.writable});
            defs.push_back(d);
            node.define_device(plc.name, std::move(d));
        }
        std::vector<sp::Message> out;
        (void)node.next_will(0);
        node.birth(0, out);
        node.attach("p", 0, out);
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static World w;
    if (size == 0) return 0;
    static const std::string topics[] = {"spBv1.0/plant/NCMD/fuzz", "spBv1.0/plant/DCMD/fuzz/p",
                                         "spBv1.0/plant/DCMD/fuzz/q",
                                         "spBv1.0/plant/DCMD/fuzz/nope"};
    const std::string& topic = topics[data[0] & 3U];
    const bool retained = (data[0] & 0x80U) != 0;
    const std::string payload(reinterpret_cast<const char*>(data + 1), size - 1);

    // 1. The Edge Node alone.
    std::vector<sp::Command> cmds;
    w.node.on_command(topic, payload, cmds);
    const bool is_ncmd = (data[0] & 3U) == 0;
    for (const auto& c : cmds) {
        if (std::holds_alternative<sp::Rebirth>(c)) {
            trap_unless(is_ncmd);
        } else if (const auto* dw = std::get_if<sp::DeviceWrite>(&c)) {
            trap_unless(!is_ncmd && dw->device == "p" && dw->index < w.defs[0].size());
            const auto& def = w.defs[0][dw->index];
            trap_unless(def.writable && def.name == dw->metric);
            trap_unless(value_fits(def.datatype, dw->value));
        } else {
            trap_unless(!std::get<sp::CommandError>(c).reason.empty());
        }
    }

    // 2. The bridge's command path, as fins-bridge runs it.
    const auto rejected = w.format->rejected_commands();
    const auto failed = w.bridge->failed_commands();
    w.rebirth = false;
    w.bridge->incoming(topic, payload, retained);
    w.io.restart();
    while (w.io.poll() > 0) {
    }
    trap_unless(w.bridge->failed_commands() == failed);
    trap_unless(w.rebirth || w.format->rejected_commands() > rejected);
    return 0;
}
