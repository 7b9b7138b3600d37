// `finsd ctl send|recv|sendcmd|instructions` (ctl_instructions.hpp).
#include "finsd/ctl_instructions.hpp"

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

namespace fins::finsd {

namespace {

using Json = nlohmann::json;

constexpr int exit_ok = 0;
constexpr int exit_usage = 2;
constexpr int exit_end_code = 4;
constexpr int exit_no_response = 5;
constexpr int exit_not_sent = 6;

struct Common {
    std::string dest, local, remote, command;
    unsigned count = 1;
    double timeout_seconds = 0;  // as `fins --timeout`: seconds, decimals allowed
    unsigned retries = 0;
    bool no_response = false;
};

void add_common(CLI::App* c, Common& o, InstructionVerbs& verbs) {
    c->add_option("--dest", o.dest, "Destination NET.NODE.UNIT, e.g. 0.5.0 (network 0 = local)");
    // Seconds, as `fins --timeout` (issue 18 newcomer 12); the instruction's field counts
    // 0.1 s (W596 3-3: 0000-FFFF), so 0.1 to 6553.5 s, and 0 = the default 2 s.
    c->add_option("--timeout", o.timeout_seconds,
                  "Response timeout in seconds, 0.1-6553.5 (decimals allowed; 0 = 2 s)")
        ->check(CLI::Range(0.0, 6553.5))
        ->check(
            [](const std::string& text) {
                double v = 0;
                try {
                    v = std::stod(text);
                } catch (const std::exception&) {
                    return std::string("not a number of seconds");
                }
                return v == 0 || v >= 0.05 ? std::string{}
                                           : std::string("a timeout is at least 0.1 s (0 = 2 s)");
            },
            "0 or 0.1-6553.5");
    c->add_option("--retries", o.retries, "Retries after a timeout, 0-15 (default 0)")
        ->check(CLI::Range(0, 15));
    c->add_flag("--no-response", o.no_response, "Send with the ICF no-response bit (not recv)");
    c->add_flag("--json", verbs.json, "Print the answer as JSON");
}

Json common_request(const char* cmd, const Common& o, InstructionVerbs& verbs) {
    const auto tenths = static_cast<unsigned>(o.timeout_seconds * 10.0 + 0.5);
    const auto per_try = std::chrono::milliseconds(100U * (tenths == 0 ? 20U : tenths));
    verbs.wait = per_try * (o.retries + 1) + std::chrono::seconds(5);
    return Json{{"cmd", cmd},
                {"dest", o.dest},
                {"timeout", tenths},  // the control protocol keeps W596's 0.1 s
                {"retries", o.retries},
                {"no_response", o.no_response}};
}

}  // namespace

void add_instruction_verbs(CLI::App& app, Json& request, InstructionVerbs& verbs) {
    auto o = std::make_shared<Common>();
    verbs.send = app.add_subcommand(
        "send", "Send: write local words to a remote node (01 02), or send one raw JSON line");
    verbs.send->add_option("json", verbs.raw, "A raw request line (starts with '{')");
    add_common(verbs.send, *o, verbs);
    verbs.send->add_option("--local", o->local, "First local word sent, e.g. D100");
    verbs.send->add_option("--remote", o->remote, "First remote word written, e.g. D200");
    verbs.send->add_option("--count", o->count, "Words, 0-990 (default 1)");
    verbs.send->callback([&request, &verbs, o] {
        if (!verbs.raw.empty()) return;
        if (o->dest.empty() || o->local.empty() || o->remote.empty())
            throw CLI::ValidationError("send",
                                       "needs --dest, --local and --remote (or one JSON line)");
        request = common_request("send", *o, verbs);
        request["local"] = o->local;
        request["remote"] = o->remote;
        request["count"] = o->count;
    });

    verbs.recv = app.add_subcommand("recv", "Rcv: read remote words into local words (01 01)");
    add_common(verbs.recv, *o, verbs);
    verbs.recv->add_option("--remote", o->remote, "First remote word read, e.g. D200")->required();
    verbs.recv->add_option("--local", o->local, "First local word written, e.g. D300")->required();
    verbs.recv->add_option("--count", o->count, "Words, 0-990 (default 1)");
    verbs.recv->callback([&request, &verbs, o] {
        if (o->dest.empty()) throw CLI::ValidationError("recv", "needs --dest");
        request = common_request("recv", *o, verbs);
        request["local"] = o->local;
        request["remote"] = o->remote;
        request["count"] = o->count;
    });

    verbs.sendcmd = app.add_subcommand("sendcmd", "SendCmd: send any command, print the answer");
    add_common(verbs.sendcmd, *o, verbs);
    verbs.sendcmd->add_option("--command", o->command, "Hex MRC SRC parameters, e.g. 0501")
        ->required();
    verbs.sendcmd->callback([&request, &verbs, o] {
        if (o->dest.empty()) throw CLI::ValidationError("sendcmd", "needs --dest");
        request = common_request("sendcmd", *o, verbs);
        request["command"] = o->command;
    });

    app.add_subcommand("instructions", "Network instruction ports in use and counters")
        ->callback([&request] {
            request = Json{{"cmd", "instructions"}};
        });
}

int print_instruction_answer(const Json& answer, const std::string& line, bool json) {
    const auto result = answer.find("result");
    if (json || result == answer.end() || !result->is_object()) {
        std::printf("%s\n", line.c_str());
    } else {
        const auto& r = *result;
        const auto text = [&](const char* key) {
            const auto it = r.find(key);
            return it != r.end() && it->is_string() ? it->get<std::string>() : std::string{};
        };
        if (r.value("done", false)) {
            std::printf("done: %s (port %s, %u transmission(s))\n", text("detail").c_str(),
                        r["port"].is_number() ? std::to_string(r["port"].get<int>()).c_str() : "-",
                        r.value("transmissions", 0U));
        } else {
            std::printf("error: ErrorID %s ErrorIDEx %s: %s\n", text("error_id").c_str(),
                        text("error_id_ex").c_str(), text("detail").c_str());
        }
        if (const auto words = r.find("words"); words != r.end() && !words->empty()) {
            std::size_t n = 0;
            for (const auto& w : *words)
                std::printf("%04X%s", w.get<unsigned>(),
                            (++n % 8 == 0 || n == words->size()) ? "\n" : " ");
        }
        if (const auto hex = text("response"); !hex.empty())
            std::printf("response: %s\n", hex.c_str());
    }
    if (result == answer.end() || !result->is_object()) {
        if (answer.value("ok", false)) return exit_ok;
        if (answer.contains("error") && answer["error"].is_string())
            std::fprintf(stderr, "finsd ctl: %s\n", answer["error"].get<std::string>().c_str());
        return exit_usage;
    }
    const auto& r = *result;
    if (r.value("done", false)) return exit_ok;
    const std::string id = r.value("error_id", std::string{});
    const std::string ex = r.value("error_id_ex", std::string{});
    if (id == "0400") return exit_usage;
    if (r.contains("end_code") && r["end_code"].is_string()) return exit_end_code;
    if (ex == "0205") return exit_no_response;
    return exit_not_sent;
}

}  // namespace fins::finsd
