// The rig of the fins-bridge end-to-end tests: one finsd PLC ("press1"), a mosquitto, a
// subscriber on t/# and the fins-bridge binary polling the PLC's "fast" group
// (bridge_fixture.hpp has the parts).
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "bridge_fixture.hpp"

namespace fins::bridge::test {

using fins::test::Finsd;

// A [[plc]] table for finsd on `port`, with short timeouts and back-off, then `extra`.
inline std::string plc(const std::string& name, std::uint16_t port, const std::string& extra = "") {
    return "[[plc]]\nname = \"" + name +
           "\"\nhost = \"127.0.0.1\"\nport = " + std::to_string(port) +
           "\ntimeout_ms = 300\nretries = 1\nbackoff_min_ms = 50\nbackoff_max_ms = 300\n" + extra;
}

inline const std::string tags = R"([[plc.group]]
name = "fast"
interval_ms = 100
tags = [ { name = "speed", address = "D100", type = "int16" },
         { name = "run",   address = "CIO0.00", type = "bool", writable = true },
         { name = "temp",  address = "D200", type = "float", writable = true, min = -50, max = 500 },
         { name = "count", address = "D202", type = "uint32", writable = true },
         { name = "recipe", address = "D210", type = "string", length = 8, writable = true },
         { name = "far",   address = "D5000", type = "int16" },
         { name = "done",  address = "T5", type = "bool" } ]
)";

struct Rig {
    ScratchDir dir{"bridge"};
    Mosquitto broker{dir.path()};
    Finsd finsd{{}};
    Recorder sub{broker.port(), "t/#"};
    std::unique_ptr<BridgeProcess> bridge;
    explicit Rig(const std::string& plc_extra = "", const std::string& group = tags) {
        bridge = std::make_unique<BridgeProcess>(
            dir, mqtt_section(broker.port()) + plc("press1", finsd.port(), plc_extra) + group);
    }
    bool ready() const { return broker.started() && finsd.started() && sub.connected(); }
};

// Whether a response answers the string id `id` (ids keep their JSON type: 5 is not "5").
inline bool answers_id(const nlohmann::json& j, const std::string& id) {
    return j.is_object() && j.contains("id") && j["id"] == id;
}

// The first answer to the write command `id`, if one comes.
inline std::optional<nlohmann::json> response(
    Recorder& sub, const std::string& id, const std::string& topic = "t/press1/write/response") {
    auto r = sub.wait_topic(topic, [&](const nlohmann::json& j) { return answers_id(j, id); });
    if (!r) return std::nullopt;
    return r->json();
}

// How many answers to `id` came so far.
inline std::size_t responses(Recorder& sub, const std::string& id) {
    std::size_t n = 0;
    for (const auto& m : sub.messages())
        if (m.topic == "t/press1/write/response" && answers_id(m.json(), id)) ++n;
    return n;
}

}  // namespace fins::bridge::test
