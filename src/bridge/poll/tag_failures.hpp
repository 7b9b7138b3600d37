// A PLC that answers but whose every tag fails (issue 26 point 15): its frames come back
// with an error end code (0201 "destination node not in network" from a PLC addressed as
// another node, 0102, 1103 ...), so the poller is online, yet no tag has a value. The
// bridge's status for it then says so (state "failing", docs/bridge.md) instead of
// "online", with the hint to set `dest`; it says "online" again once a tag has a value.
//
// Only end codes count: a frame that times out makes the PLC offline (poller.hpp), and
// the cycles failed by going offline are not a PLC answering with errors.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <system_error>
#include <unordered_map>
#include <vector>

#include "bridge/payload.hpp"
#include "fins/frame.hpp"

namespace fins::bridge {

class TagFailures {
  public:
    // A group's cycle of a PLC whose last status is `current` (online: the poller's) and
    // whose frames go to `destination`. The PLC's new status when it changes: failing
    // (every group's last cycle had every tag failing with an end code) or online again.
    std::optional<PlcStatus> cycle(const GroupSample& sample, const PlcStatus& current,
                                   NodeAddress destination);
    // Forgets the PLC's cycles (a status of the poller: online, offline).
    void reset(const Plc* plc) { plcs_.erase(plc); }

  private:
    enum class Outcome : std::uint8_t { unknown, some_value, all_end_codes };
    struct PlcCycles {
        std::vector<Outcome> groups;
        std::error_code first;  // an end code of the last failed cycle
    };
    // Only PLCs with a group whose last cycle failed with end codes have an entry: a PLC
    // whose cycles bring values costs one look-up by address a cycle, nothing else.
    std::unordered_map<const Plc*, PlcCycles> plcs_;
};

// The text of a failing status: the end code, the node the frames go to and why, and
// the `dest` hint.
std::string failing_text(const Plc& plc, std::error_code end_code, NodeAddress destination);

}  // namespace fins::bridge
