// The payload seam: how a group's values, a PLC's status and write responses become MQTT
// messages, and how incoming commands are parsed. JsonPayload (json_payload.*) is the
// default; a Sparkplug B format implements the same interface.
//
// All calls come from the bridge's io_context thread. `out` receives the messages to
// publish; formats keep whatever state they need (Sparkplug's seq, bdSeq, births).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "bridge/config.hpp"
#include "bridge/tag_type.hpp"
#include "fins/error.hpp"

namespace fins::bridge {

// An error as users read it: for a FINS end code its code, name and probable cause from
// libfins' end-code table (W342 5-1-3): "1103 address range error: the start address is
// beyond the accessible area"; otherwise the error's message ("no response within the
// timeout").
inline std::string error_text(std::error_code ec) {
    if (ec.category() == end_code_category())
        if (const auto* info = find_end_code(static_cast<std::uint16_t>(ec.value())))
            return describe(ec) + ": " + std::string(info->message);
    return describe(ec);
}

struct Message {
    std::string topic;
    std::string payload;
    int qos = 0;
    bool retain = false;
};
using Sink = std::function<void(Message&&)>;

// One tag's outcome in a poll cycle: a value, or why there is none (FINS end code,
// timeout ...). A failed tag never carries its last value.
struct TagSample {
    TagValue value;
    std::error_code error;  // empty: value is fresh
    bool changed = false;   // publish it in change mode (not set in `always` groups)
};

// A completed poll cycle of one group.
struct GroupSample {
    const Plc* plc = nullptr;
    const Group* group = nullptr;
    std::span<const TagSample> tags;  // in the group's tag order
    std::int64_t ts_ms = 0;           // when the last answer arrived (ms since the epoch)
    bool full = false;                // every tag, not only the changed ones
};

struct PlcStatus {
    const Plc* plc = nullptr;
    bool online = false;
    std::string last_error;  // empty when none
    std::int64_t ts_ms = 0;
    // Online, but every tag fails with an end code (tag_failures.hpp): state "failing",
    // last_error says why and what to set.
    bool failing = false;
};

// A write command, parsed. `id` is the caller's; `tag` a tag name of the PLC.
struct WriteCommand {
    std::string plc;
    std::string id;
    std::string tag;
    nlohmann::json value;
    std::optional<std::int64_t> ts_ms;  // when the sender made it, if it says
};

struct WriteResponse {
    std::string id;
    bool ok = false;
    std::optional<std::uint16_t> end_code;  // the PLC's answer, when one came
    std::optional<nlohmann::json> value;    // read back after the write
    std::string error;                      // empty when ok
};

// What an incoming message turned out to be: exactly one of these, and the bridge handles
// every alternative (Bridge::command visits it; a new alternative does not compile until it
// is handled there).
//   WriteCommand  a write to execute (the write path still checks tag, value, TTL, PLC);
//   Refusal       a bad write command, answered at once on its PLC's response topic (JSON);
//   NodeRebirth   Sparkplug NCMD "Node Control/Rebirth" = true: the birth sequence again;
//   Rejected      a command addressed to this instance that is not executed and has no
//                 response topic (Sparkplug): PayloadFormat::rejected() logs and counts it.
struct Refusal {
    std::string plc;         // the PLC it concerns (for the answer topic)
    WriteResponse response;  // ok false, the reason in error
};
struct NodeRebirth {};
struct Rejected {
    std::string reason;
};
using ParsedCommand = std::variant<WriteCommand, Refusal, NodeRebirth, Rejected>;

class PayloadFormat {
  public:
    virtual ~PayloadFormat() = default;
    // Topics to subscribe to for commands.
    [[nodiscard]] virtual std::vector<std::string> subscriptions() const = 0;
    // The bridge's own status: the Will (online = false) and what is published on
    // every connect (online = true).
    [[nodiscard]] virtual Message bridge_status(bool online) const = 0;
    // Called after every (re)connect, before data flows (Sparkplug: NBIRTH/DBIRTH).
    virtual void connected(const Sink& out) { (void)out; }
    virtual void values(const GroupSample& sample, const Sink& out) = 0;
    virtual void status(const PlcStatus& status, const Sink& out) = 0;
    virtual void write_response(const Plc& plc, const WriteResponse& r, const Sink& out) = 0;
    // The PLC is no longer polled here (another instance owns it now).
    virtual void released(const Plc& plc, const Sink& out) {
        (void)plc;
        (void)out;
    }
    // A format whose session rules need an MQTT connection of its own (Sparkplug B: the
    // Edge Node's NDEATH must be the connection's Will, with a bdSeq that changes on every
    // CONNECT) says so here. Its subscriptions and messages then travel on that second
    // connection, and the bridge's status and membership stay on the first.
    [[nodiscard]] virtual bool own_session() const { return false; }
    // The Will for the session's next CONNECT (asked for by the MQTT client before each one,
    // on the bridge's thread).
    virtual Message session_will() { return {}; }
    // Published on the session before a clean disconnect.
    [[nodiscard]] virtual Message session_goodbye() const { return {}; }
    // Parses a message on one of subscriptions(); nullopt when it is not for this format.
    virtual std::optional<ParsedCommand> parse(std::string_view topic, std::string_view payload,
                                               bool retained) = 0;
    // A command on `topic` that is not executed and has no answer topic (a Rejected, or a
    // NodeRebirth/Rejected whose handling failed): the format logs and counts it.
    virtual void rejected(std::string_view topic, std::string_view reason) {
        (void)topic;
        (void)reason;
    }
    // Commands refused or failed so far, for the bridge's stats ("commands_rejected").
    [[nodiscard]] virtual std::uint64_t rejected_commands() const { return 0; }
};

}  // namespace fins::bridge
