// The control verbs' one dispatcher (contract in control_dispatch.hpp).
#include "server/control/control_dispatch.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <exception>
#include <memory>

#include <fmt/core.h>

#include "server/control/control_requests.hpp"
#include "server/control/control_scenario.hpp"
#include "server/sessions/failure_boundary.hpp"

namespace fins::server {

using Json = nlohmann::json;

namespace {

std::atomic<ControlFault> control_fault{nullptr};

}  // namespace

void set_control_fault_for_tests(ControlFault fault) noexcept {
    control_fault.store(fault, std::memory_order_relaxed);
}

std::optional<std::pair<std::uint8_t, std::uint8_t>> parse_net_node(std::string_view text) {
    const auto dot = text.find('.');
    if (dot == std::string_view::npos) return std::nullopt;
    unsigned net = 0;
    unsigned node = 0;
    const char* b = text.data();
    const char* e = text.data() + text.size();
    const auto r1 = std::from_chars(b, b + dot, net);
    const auto r2 = std::from_chars(b + dot + 1, e, node);
    if (r1.ec != std::errc{} || r1.ptr != b + dot || r2.ec != std::errc{} || r2.ptr != e ||
        dot == 0 || net > 0xFF || node > 0xFF)
        return std::nullopt;
    return std::pair{static_cast<std::uint8_t>(net), static_cast<std::uint8_t>(node)};
}

const ControlTarget* find_control_target(std::span<const ControlTarget> targets,
                                         std::optional<std::string_view> wanted, std::string& why) {
    if (targets.empty()) {
        why = "no CPU Unit";
        return nullptr;
    }
    if (!wanted) return &targets.front();
    for (const auto& t : targets)
        if (!t.name.empty() && t.name == *wanted) return &t;
    if (const auto address = parse_net_node(*wanted))
        for (const auto& t : targets)
            if (std::find(t.addresses.begin(), t.addresses.end(), *address) != t.addresses.end())
                return &t;
    std::string known;
    for (const auto& t : targets)
        if (!t.name.empty()) known += (known.empty() ? "" : ", ") + t.name;
    why = fmt::format("no CPU Unit \"{}\" here{}", *wanted,
                      known.empty() ? std::string(" (a single node: leave \"plc\" out)")
                                    : " (CPU Units: " + known + ")");
    return nullptr;
}

namespace {

void dispatch_unguarded(std::span<const ControlTarget> targets, const Json& j,
                        const ControlReply& reply) {
    if (const auto fault = control_fault.load(std::memory_order_relaxed)) fault(j);
    if (!j.is_object() || !j.contains("cmd") || !j["cmd"].is_string())
        return reply(control_error("expected an object with a string \"cmd\""));
    std::optional<std::string_view> wanted;
    if (const auto it = j.find("plc"); it != j.end() && !it->is_null()) {
        if (!it->is_string())
            return reply(
                control_error("\"plc\" must be a CPU Unit's name or its FINS address NET.NODE"));
        wanted = it->get_ref<const std::string&>();
    }
    std::string why;
    const ControlTarget* target = find_control_target(targets, wanted, why);
    if (target == nullptr) return reply(control_error(why));
    Json answer;
    try {
        if (handle_instruction_request(target->instructions, target->schedule, j, reply)) return;
        // A scenario verb may answer later (an advance runs in slices).
        if (j["cmd"] == "scenario") {
            return handle_scenario_request(target->scenario, j,
                                           [reply, name = target->name](Json a) {
                                               if (!name.empty() && a.contains("status"))
                                                   a["status"]["plc"] = name;
                                               reply(std::move(a));
                                           });
        }
        answer = handle_control_request(*target->plc, j);
    } catch (const Json::exception& e) {
        // A key of the wrong type (handle_control_request's contract): the client's
        // mistake. Anything else a verb throws is this server's: the boundary below.
        answer = control_error(std::string("bad request: ") + e.what());
    }
    if (!target->name.empty() && answer.contains("status")) answer["status"]["plc"] = target->name;
    reply(std::move(answer));
}

std::string command_of(const Json& j) {
    if (j.is_object())
        if (const auto it = j.find("cmd"); it != j.end() && it->is_string())
            return "control request \"" + it->get<std::string>() + "\"";
    return "a control request";
}

}  // namespace

void dispatch_control_request(std::span<const ControlTarget> targets, const Json& j,
                              const ControlReply& reply) {
    // The failure boundary (sessions/failure_boundary.hpp): `reply` is called exactly
    // once whatever throws, and nothing thrown leaves this function, neither now nor
    // when an instruction's answer comes later.
    std::shared_ptr<bool> answered;
    // Calls `reply` unless it was called; what the caller's reply throws is counted.
    const auto answer_once = [](const ControlReply& to, bool& done, Json answer) noexcept {
        if (done) return;
        done = true;
        try {
            to(std::move(answer));
        } catch (...) {
            note_failure(FailureChannel::control, "the answer to a control request",
                         "an exception while the answer was sent");
        }
    };
    try {
        answered = std::make_shared<bool>(false);
        const ControlReply once = [reply, answered, answer_once](Json answer) {
            answer_once(reply, *answered, std::move(answer));
        };
        dispatch_unguarded(targets, j, once);
    } catch (...) {
        std::string what = "an exception";
        std::string where = "a control request";
        try {
            what = describe_exception(std::current_exception());
            where = command_of(j);
        } catch (...) {
            // Out of memory for the text: the defaults say enough.
        }
        note_failure(FailureChannel::control, where, what);
        bool never_answered = false;  // no memory even for the flag: nothing was answered
        bool& done = answered != nullptr ? *answered : never_answered;
        try {
            Json answer = control_error("internal error: " + what);
            answer["internal"] = true;
            answer_once(reply, done, std::move(answer));
        } catch (...) {
            // No memory for the answer: the counter and the log line have it.
        }
    }
}

}  // namespace fins::server
