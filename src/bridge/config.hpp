// fins-bridge's configuration: the TOML contract of issue 17 (docs/bridge.md "Configuration").
//
// load_config() reads and validates the whole file before anything starts. Every error
// is one line "file:line:col: message" naming the key or value at fault: unknown keys,
// names outside [A-Za-z0-9_-]+, duplicate names, addresses the PLC model does not have,
// tags that do not fit one frame, bad types and out-of-range numbers. The program exits 2
// on such an error (src/cli/fins-bridge/main.cpp).
//
// Addresses are parsed by libfins (fins/address.hpp) and checked against the memory-area
// table (fins/memory_area.hpp) and the model's sizes (plc::Profile): one source of truth.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <tl/expected.hpp>

#include "bridge/tag_type.hpp"
#include "fins/address.hpp"
#include "fins/frame.hpp"
#include "fins/memory_area.hpp"

namespace fins::bridge {

struct Tag {
    std::string name;
    std::string address_text;  // as configured, for --plan and errors
    Address address;
    TagType type = TagType::int16;
    std::size_t length = 0;  // string tags: characters
    bool writable = false;
    std::optional<double> deadband;  // overrides the group's
    Range range;                     // writes outside [min, max] are refused

    // How the planner reads it (resolved by the config loader):
    // flag == false: `words` words from `read_start` (a word area code, 2-byte elements);
    //                a bool takes bit `address.bit` of its word.
    // flag == true:  one 1-byte element at `read_start` (T/C completion flag, task flag),
    //                only through 01 04.
    MemoryAddress read_start;
    std::size_t words = 1;
    bool flag = false;
};

enum class Publish : std::uint8_t { change, always };

struct Group {
    std::string name;
    std::chrono::milliseconds interval{1000};
    Publish publish = Publish::change;
    double deadband = 0;                 // absolute, numeric tags, change mode
    std::chrono::seconds integrity{60};  // full snapshot at least this often (change)
    std::size_t gap_words = 16;          // planner: merge runs closer than this
    std::vector<Tag> tags;
};

enum class Transport : std::uint8_t { udp, tcp };

struct Plc {
    std::string name;
    std::string host;
    std::uint16_t port = 9600;
    Transport transport = Transport::udp;
    std::optional<NodeAddress> dest;  // nullopt: node from the host's IP (as fins::Client)
    std::string model = "cj2h";
    std::chrono::milliseconds timeout{1000};  // per frame
    unsigned retries = 1;                     // resends before the frame fails
    std::size_t window = 4;                   // frames in flight to this PLC
    std::chrono::milliseconds backoff_min{500};
    std::chrono::milliseconds backoff_max{30000};
    std::vector<Group> groups;

    // The tag named `tag` of any group; null when there is none.
    [[nodiscard]] const Tag* find_tag(std::string_view tag) const {
        for (const auto& g : groups)
            for (const auto& t : g.tags)
                if (t.name == tag) return &t;
        return nullptr;
    }
};

struct Broker {
    std::string host;
    std::uint16_t port = 1883;
};

struct Mqtt {
    std::vector<Broker> brokers;  // host/port, or hosts = ["h1:1883", "h2"]: tried in turn
    std::string client_id;        // default: fins-bridge-{instance}
    std::string username;
    std::string password;
    std::string ca_file;  // TLS on when set
    std::string cert_file;
    std::string key_file;
    bool tls_insecure = false;  // do not check the broker's host name
    std::chrono::seconds keepalive{30};
    std::string topic_prefix = "finskit";
    int qos = 0;                      // data messages; status and responses use 1
    std::size_t queue_limit = 10000;  // messages handed to the client and not yet sent
    std::chrono::milliseconds backoff_min{500};
    std::chrono::milliseconds backoff_max{30000};
};

struct WriteRules {
    std::chrono::milliseconds ttl{10000};     // older commands are refused
    std::size_t id_memory = 1024;             // command ids remembered per PLC
    std::chrono::milliseconds ts_skew{5000};  // a "ts" further ahead than this is refused
};

struct BridgeConfig {
    std::string source;  // the file name, for messages
    std::string instance;
    std::chrono::seconds failover{10};
    std::chrono::seconds stats{10};  // {prefix}/$bridge/{instance}/stats every this often
    std::string payload = "json";    // "json" | "sparkplug" (PayloadFormat, payload.hpp)
    std::string sparkplug_group;     // Sparkplug group_id; default: topic_prefix
    Mqtt mqtt;
    WriteRules write;
    std::vector<Plc> plcs;
};

// Parses TOML text; `source` names it in messages. `instance` (from --instance) wins
// over [bridge] instance; both empty: the host name.
tl::expected<BridgeConfig, std::string> parse_config(const std::string& text,
                                                     const std::string& source,
                                                     const std::string& instance = {});
tl::expected<BridgeConfig, std::string> load_config(const std::string& path,
                                                    const std::string& instance = {});

// [A-Za-z0-9_-]+
bool valid_name(std::string_view name);

}  // namespace fins::bridge
