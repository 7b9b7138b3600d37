// The bridge: one PlcPoller per configured PLC on one io_context, a PayloadFormat that
// turns their results into messages, an MqttClient that carries them, and the write path.
//
//   PLC --FINS--> PlcPoller (plan, window, timeouts) --GroupSample--> PayloadFormat
//       --Message--> MqttClient --> broker
//   broker --> MqttClient --> Bridge::command --> PlcPoller::write
//
// One thread: the pollers, the MQTT clients (mqtt.hpp) and the write path all run on the
// io_context's thread, so nothing here is shared with another thread.
//
// Ownership (ownership.hpp) decides which PLCs this instance polls: reconcile() starts
// and stops pollers when it changes, and a write is executed only for an owned PLC.
//
// Writes (docs/bridge.md "Writes"): a command is refused, with an answer and without
// touching the PLC, when it is retained, not JSON, names an unknown or read-only tag,
// has a value of the wrong type or out of range, is older than [write] ttl_s (its "ts",
// or the time it waited here), has a "ts" more than [write] ts_skew_s ahead, names a PLC
// the configuration does not have, or the PLC is offline. Its id (its JSON text: 5 and "5"
// differ) is remembered (the last [write] id_memory ids per configured PLC, nothing for
// other names): a repeated id is answered again with the first answer, never executed
// again; while the first is still running the repeat gets no answer of its own (the first
// one's answer is on the same topic). Commands that arrive before the Ownership has joined
// (a persistent session's queued writes come right after CONNACK) wait for it, bounded.
//
// Commands: the format parses a message into one ParsedCommand alternative (payload.hpp) and
// command() visits it whole: a write to execute, a refusal to answer, a Sparkplug rebirth, a
// Sparkplug command rejected (logged and counted by the format). Each message is handled
// inside a failure boundary (handle()): an exception becomes a refusal where one can be
// answered, a log line (at most one a second) and a count ("commands_failed"), never the end
// of the process.
#pragma once

#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "bridge/config.hpp"
#include "bridge/mqtt.hpp"
#include "bridge/ownership.hpp"
#include "bridge/payload.hpp"
#include "bridge/poll/poller.hpp"
#include "bridge/poll/tag_failures.hpp"

namespace fins::bridge {

// Commands held until this instance has joined (below); more are dropped (and counted).
inline constexpr std::size_t max_pending_commands = 1024;

class Bridge final : public PollerEvents {
  public:
    Bridge(asio::io_context& io, const BridgeConfig& config, std::unique_ptr<PayloadFormat> format,
           std::unique_ptr<Ownership> ownership);
    ~Bridge() override;

    // Connects MQTT and starts polling the owned PLCs. False with the reason on a
    // start-up failure.
    bool start(std::string& error);
    // Stops polling, publishes the offline status and disconnects.
    void stop();
    // A broker's name is being looked up (MqttClient::looking_up()).
    [[nodiscard]] bool looking_up() const noexcept;
    // Starts polling owned PLCs that are not polled and stops the others.
    void reconcile();

    // Incoming MQTT message (on the io_context's thread, from the MQTT client): handled at
    // once.
    void incoming(std::string topic, std::string payload, bool retained);

    [[nodiscard]] PayloadFormat& format() noexcept { return *format_; }
    [[nodiscard]] Ownership& ownership() noexcept { return *ownership_; }
    [[nodiscard]] MqttClient* mqtt() noexcept { return mqtt_.get(); }
    [[nodiscard]] asio::io_context& io() noexcept { return io_; }
    // What the bridge holds for commands (tests of the bounds, docs/bridge.md "Bounds"):
    // PLCs with remembered ids, remembered ids in all, commands waiting for the join, and
    // commands dropped at a bound.
    [[nodiscard]] std::size_t remembered_plcs() const noexcept { return ids_.size(); }
    [[nodiscard]] std::size_t remembered_ids() const noexcept;
    [[nodiscard]] std::size_t held_commands() const noexcept { return held_.size(); }
    [[nodiscard]] std::uint64_t dropped_commands() const noexcept { return dropped_commands_; }

    // Test hook: called with every parsed command before it is handled (a test makes it
    // throw to prove the failure boundary below).
    void set_command_hook(std::function<void(const ParsedCommand&)> hook) {
        command_hook_ = std::move(hook);
    }
    // Messages whose handling threw (each one refused where it can be answered, logged at
    // most once a second, and counted here: "commands_failed" in the stats).
    [[nodiscard]] std::uint64_t failed_commands() const noexcept { return failed_commands_; }

    void group_done(const GroupSample& sample) override;
    void status_changed(const PlcStatus& status) override;
    void write_done(const Plc& plc, const WriteResponse& response) override;

  private:
    struct IdMemory {
        struct Entry {
            bool done = false;
            WriteResponse response;
        };
        std::unordered_map<std::string, Entry> entries;
        std::deque<std::string> order;  // oldest first
    };

    struct Held {
        std::string topic;
        std::string payload;
        bool retained = false;
        std::chrono::steady_clock::time_point arrival;
    };

    // One MQTT message, inside the failure boundary: nothing it throws leaves handle().
    void handle(const std::string& topic, const std::string& payload, bool retained,
                std::chrono::steady_clock::time_point arrival) noexcept;
    void command(const std::string& topic, const std::string& payload, bool retained,
                 std::chrono::steady_clock::time_point arrival,
                 std::optional<ParsedCommand>& parsed);
    void execute(const WriteCommand& w, std::chrono::steady_clock::time_point arrival);
    void refuse(const Refusal& r, bool retained);
    void rebirth();
    // The birth sequence for the MQTT connection of `generation`, if it is still the one.
    void births(std::uint64_t generation);
    void failed(const std::string& topic, bool retained, const std::optional<ParsedCommand>& parsed,
                std::string_view what) noexcept;
    // Commands that came before this instance joined, handled in order once it has.
    void release_held();
    void answer(const Plc& plc, const WriteResponse& r);
    IdMemory::Entry& remember(const std::string& plc, const std::string& id);
    void publish(Message&& m);
    void report();

    asio::io_context& io_;
    const BridgeConfig& config_;
    std::unique_ptr<PayloadFormat> format_;
    std::unique_ptr<Ownership> ownership_;
    std::unique_ptr<MqttClient> mqtt_;
    std::unique_ptr<MqttClient> session_;  // the format's own connection (own_session())
    Sink sink_;
    std::map<std::string, std::unique_ptr<PlcPoller>, std::less<>> pollers_;
    TagFailures tag_failures_;  // PLCs online whose every tag fails
    std::map<std::string, PlcStatus, std::less<>> statuses_;
    // A cycle's look-up (group_done), by the configured PLC's address: its poller and its
    // entry in statuses_ (null until its first status, and after it is released).
    struct PlcEntry {
        PlcPoller* poller = nullptr;
        const PlcStatus* status = nullptr;
    };
    std::unordered_map<const Plc*, PlcEntry> by_plc_;
    std::map<std::string, IdMemory, std::less<>> ids_;
    std::deque<Held> held_;  // at most max_pending_commands
    std::uint64_t dropped_commands_ = 0;
    std::uint64_t failed_commands_ = 0;
    std::uint64_t failures_unlogged_ = 0;  // since the last failure log line
    std::chrono::steady_clock::time_point last_failure_log_{};
    std::function<void(const ParsedCommand&)> command_hook_;
    asio::steady_timer report_timer_;
    std::chrono::steady_clock::time_point last_report_;
    PollerStats last_totals_{};
    bool stopped_ = false;
};

}  // namespace fins::bridge
