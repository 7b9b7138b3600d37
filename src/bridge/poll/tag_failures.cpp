// A PLC whose every tag fails (see tag_failures.hpp).
#include "bridge/poll/tag_failures.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace fins::bridge {

std::optional<PlcStatus> TagFailures::cycle(const GroupSample& sample, const PlcStatus& current,
                                            NodeAddress destination) {
    if (sample.plc == nullptr || sample.group == nullptr || !current.online) return std::nullopt;
    const auto& groups = sample.plc->groups;
    std::size_t g = 0;
    while (g < groups.size() && &groups[g] != sample.group)
        ++g;
    if (g == groups.size()) return std::nullopt;
    const auto end_code = [](const TagSample& t) {
        return t.error && t.error.category() == end_code_category();
    };
    const bool all_failed =
        !sample.tags.empty() && std::all_of(sample.tags.begin(), sample.tags.end(), end_code);
    auto found = plcs_.find(sample.plc);
    if (!all_failed) {
        if (std::none_of(sample.tags.begin(), sample.tags.end(),
                         [](const TagSample& t) { return !t.error; }))
            return std::nullopt;  // timeouts, or no tag: going offline says why
        // A value: not failing. Nothing to remember unless an earlier cycle failed.
        if (found == plcs_.end())
            return current.failing ? std::optional<PlcStatus>(
                                         PlcStatus{sample.plc, true, "", sample.ts_ms, false})
                                   : std::nullopt;
        found->second.groups[g] = Outcome::some_value;
    } else {
        if (found == plcs_.end()) found = plcs_.emplace(sample.plc, PlcCycles{}).first;
        found->second.groups.resize(groups.size(), Outcome::unknown);
        found->second.first = sample.tags.front().error;
        found->second.groups[g] = Outcome::all_end_codes;
    }
    const auto& cycles = found->second;
    const bool failing = std::all_of(cycles.groups.begin(), cycles.groups.end(),
                                     [](Outcome o) { return o == Outcome::all_end_codes; });
    if (failing == current.failing) return std::nullopt;
    PlcStatus next{sample.plc, true, "", sample.ts_ms, failing};
    if (failing) next.last_error = failing_text(*sample.plc, cycles.first, destination);
    return next;
}

std::string failing_text(const Plc& plc, std::error_code end_code, NodeAddress destination) {
    const char* why = plc.dest                          ? "its dest"
                      : plc.transport == Transport::tcp ? "the node the FINS/TCP handshake named"
                                                        : "the last number of its IP address";
    const std::string port = plc.port == 9600 ? "" : fmt::format(" --port {}", plc.port);
    return fmt::format(
        "every tag fails: {}; requests go to node {}.{}.{} ({}): if the PLC is another node, "
        "set dest = \"NET.NODE.UNIT\" for plc \"{}\" (`fins --host {}{} probe` tells its "
        "node)",
        error_text(end_code), destination.network, destination.node, destination.unit, why,
        plc.name, plc.host, port);
}

}  // namespace fins::bridge
