// Fuzzes fins-bridge's cluster membership (src/bridge/cluster/membership.hpp) with the
// status messages any client of the broker can publish: a sequence of (instance, payload)
// pairs, and the topic parser. The member list stays sorted, unique, bounded (max_members
// besides self), holds self only when synced, and ownership answers are consistent: every
// PLC has one live owner when there are members, and this instance owns it only if it is
// that owner.
//
// Input: lines "instance\tpayload"; a line "!" is a lost connection; the first line is
// also tried as a topic.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <spdlog/spdlog.h>

#include "bridge/cluster/membership.hpp"

namespace {

namespace cl = fins::bridge::cluster;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

void invariants(const cl::Membership& m) {
    const auto& live = m.members();
    check(std::is_sorted(live.begin(), live.end()));
    check(std::adjacent_find(live.begin(), live.end()) == live.end());
    check(live.size() <= cl::max_members + 1);
    check(m.known() <= cl::max_members + 1);
    const bool self_live = std::find(live.begin(), live.end(), m.self()) != live.end();
    check(!self_live || m.synced());
    for (const char* plc : {"press1", "p", ""}) {
        const auto owner = m.owner(plc);
        check(live.empty() == owner.empty());
        check(!m.owns(plc) || owner == m.self());
        if (m.synced() && self_live) check(m.owns(plc) == (owner == m.self()));
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const bool quiet = [] {
        spdlog::set_level(spdlog::level::off);
        return true;
    }();
    (void)quiet;
    std::string_view in(reinterpret_cast<const char*>(data), size);
    cl::Membership m("self");
    bool first = true;
    std::size_t lines = 0;
    while (!in.empty() && lines++ < 600) {
        const auto nl = in.find('\n');
        const auto line = in.substr(0, nl);
        in = nl == std::string_view::npos ? std::string_view{} : in.substr(nl + 1);
        if (first) {
            first = false;
            if (auto i = cl::status_topic_instance("f", line)) {
                check(!i->empty() && i->find('/') == std::string_view::npos);
                check(cl::status_topic("f", *i) == line);
            }
        }
        if (line == "!") {
            m.connection_lost();
            check(!m.synced());
        } else {
            const auto tab = line.find('\t');
            const auto instance = line.substr(0, tab);
            const auto payload =
                tab == std::string_view::npos ? std::string_view{} : line.substr(tab + 1);
            const auto changes = m.changes();
            const bool changed = m.on_status(instance, payload);
            check(m.changes() == changes + (changed ? 1 : 0));
        }
        if (lines % 16 == 0) invariants(m);
    }
    invariants(m);
    return 0;
}
