// fins_bridge_peers_counter: the independent subscriber of bench/bridge_peers.sh (issue 27).
// Subscribes to TOPIC on a local broker and, for --seconds from its SUBACK, counts every
// tag value that reaches it: the data messages are `{"ts":ms,"values":{"name":v,...}}`
// (fins-bridge's JSON and the Node.js peer's alike), a value that is an object is a tag
// error and counted apart. It measures, from each data message's `ts` (the gateway's
// clock when the FINS answer arrived) to its arrival here (same host, same clock), the
// latency percentiles; and it keeps the first and the last stats message of the window
// (any topic with a `$` segment ending in /stats: `values` and `overruns` counters) so
// that the gateway's own overruns in the window are their difference. --watch NAME=PID
// (repeatable): the CPU (utime + stime of /proc/PID/stat) each process used over the same
// window, in % of one core, and its RSS at the end. Prints one JSON line on stdout.
//
//   fins_bridge_peers_counter --port 1883 --topic 'bridge/#' --seconds 20 --watch gateway=123
#include <mosquitto.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

double cpu_seconds(int pid) {
    std::ifstream f(fmt::format("/proc/{}/stat", pid));
    std::string s((std::istreambuf_iterator<char>(f)), {});
    const auto close = s.rfind(')');
    if (close == std::string::npos) return -1;
    std::istringstream rest(s.substr(close + 2));
    std::string field;
    unsigned long utime = 0, stime = 0;
    for (int i = 3; i <= 15 && rest >> field; ++i) {
        if (i == 14) utime = std::stoul(field);
        if (i == 15) stime = std::stoul(field);
    }
    return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

double rss_mib(int pid) {
    std::ifstream f(fmt::format("/proc/{}/status", pid));
    for (std::string line; std::getline(f, line);)
        if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
    return -1;
}

double epoch_ms() {
    return std::chrono::duration<double, std::milli>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
}

// The tag values of one `{"ts":..,"values":{...}}` payload: counted by one pass over the
// bytes rather than parsed (a million values a second must not cost the host a core).
// A value is a member of the "values" object; one that is an object is an error.
struct Scan {
    std::uint64_t values = 0;
    std::uint64_t errors = 0;
    double ts = -1;
    std::string_view first;  // the first value's text
    bool ok = false;
};

Scan scan(std::string_view p) {
    Scan out;
    if (const auto t = p.find("\"ts\":"); t != std::string_view::npos) {
        double v = 0;
        std::size_t i = t + 5;
        while (i < p.size() && p[i] >= '0' && p[i] <= '9')
            v = v * 10 + (p[i++] - '0');
        if (i > t + 5) out.ts = v;
    }
    const auto at = p.find("\"values\":{");
    if (at == std::string_view::npos) return out;
    int depth = 1;
    bool in_string = false, member_value = false;
    for (std::size_t i = at + 10; i < p.size() && depth > 0; ++i) {
        const char c = p[i];
        if (in_string) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                in_string = false;
            continue;
        }
        switch (c) {
            case '"':
                in_string = true;
                break;
            case ':':
                if (depth == 1) member_value = true;
                break;
            case '{':
            case '[':
                if (depth == 1 && member_value && c == '{') ++out.errors, member_value = false;
                ++depth;
                break;
            case '}':
            case ']':
                --depth;
                if (depth == 0) out.ok = true;
                break;
            default:
                if (depth == 1 && member_value && c != ' ') {
                    if (out.values++ == 0) {
                        std::size_t end = i;
                        while (end < p.size() && p[end] != ',' && p[end] != '}')
                            ++end;
                        out.first = p.substr(i, end - i);
                    }
                    member_value = false;
                }
        }
    }
    return out;
}

struct Watched {
    std::string name;
    int pid = 0;
    double cpu0 = 0;
};

// One topic's messages in the window, and how many of them repeated the first value of
// the message before (the scenario moves every word every tick: a repeat is a cycle that
// read the same tick twice, or a gateway publishing stale values).
struct TopicCount {
    std::uint32_t messages = 0;
    std::uint32_t repeats = 0;
    std::string first;
};

struct Counter {
    double seconds = 20;
    bool started = false;
    bool done = false;
    Clock::time_point t0{};
    double epoch0 = 0;
    std::vector<Watched> watched;
    std::vector<std::uint64_t> per_second;
    std::uint64_t values = 0, errors = 0, messages = 0, malformed = 0, before = 0;
    std::vector<float> latency_ms;
    std::unordered_map<std::string, TopicCount> per_topic;
    json first_stats, last_stats;
};

void on_message(mosquitto*, void* p, const mosquitto_message* m) {
    auto& c = *static_cast<Counter*>(p);
    if (!c.started || c.done) {
        ++c.before;
        return;
    }
    const auto now = Clock::now();
    const double arrived = epoch_ms();
    const double in = std::chrono::duration<double>(now - c.t0).count();
    if (in >= c.seconds) {
        c.done = true;
        return;
    }
    const std::string_view topic(m->topic);
    const std::string_view payload(static_cast<const char*>(m->payload),
                                   static_cast<std::size_t>(m->payloadlen));
    if (topic.find("/$") != std::string_view::npos) {
        if (topic.ends_with("/stats")) {
            auto j = json::parse(payload, nullptr, false);
            if (j.is_object()) {
                if (c.first_stats.is_null()) c.first_stats = j;
                c.last_stats = std::move(j);
            }
        }
        return;
    }
    if (topic.ends_with("/status")) return;
    const Scan s = scan(payload);
    if (!s.ok) {
        ++c.malformed;
        return;
    }
    ++c.messages;
    auto& t = c.per_topic[std::string(topic)];
    ++t.messages;
    if (t.messages > 1 && t.first == s.first) ++t.repeats;
    t.first = s.first;
    c.values += s.values;
    c.errors += s.errors;
    const auto second = static_cast<std::size_t>(in);
    if (second < c.per_second.size()) c.per_second[second] += s.values;
    if (s.ts >= 0) c.latency_ms.push_back(static_cast<float>(arrived - s.ts));
}

std::uint64_t counter_of(const json& stats, const char* key) {
    if (!stats.is_object() || !stats.contains(key) || !stats[key].is_number()) return 0;
    return stats[key].get<std::uint64_t>();
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_bridge_peers_counter: counts the tag values that reach a subscriber"};
    int port = 1883;
    std::string topic = "#";
    std::string label = "gateway";
    std::vector<std::string> watch;
    Counter c;
    app.add_option("--port", port, "the broker's port on 127.0.0.1");
    app.add_option("--topic", topic, "the subscription");
    app.add_option("--seconds", c.seconds, "the counting window, from the SUBACK");
    app.add_option("--label", label, "the name in the JSON line");
    app.add_option("--watch", watch, "NAME=PID: a process whose CPU and RSS to measure");
    CLI11_PARSE(app, argc, argv);
    for (const auto& w : watch) {
        const auto eq = w.find('=');
        if (eq == std::string::npos) {
            fmt::print(stderr, "--watch {}: expected NAME=PID\n", w);
            return 2;
        }
        c.watched.push_back({w.substr(0, eq), std::stoi(w.substr(eq + 1)), 0});
    }
    c.watched.push_back({"counter", static_cast<int>(::getpid()), 0});
    c.per_second.assign(static_cast<std::size_t>(c.seconds) + 1, 0);

    mosquitto_lib_init();
    mosquitto* sub = mosquitto_new(nullptr, true, &c);
    mosquitto_message_callback_set(sub, on_message);
    // The SUBACK starts the window.
    mosquitto_subscribe_callback_set(sub, [](mosquitto*, void* p, int, int, const int*) {
        auto& k = *static_cast<Counter*>(p);
        k.t0 = Clock::now();
        k.epoch0 = epoch_ms();
        for (auto& w : k.watched)
            w.cpu0 = cpu_seconds(w.pid);
        k.started = true;
    });
    if (mosquitto_connect(sub, "127.0.0.1", port, 60) != MOSQ_ERR_SUCCESS) {
        fmt::print(stderr, "cannot connect to the broker on 127.0.0.1:{}\n", port);
        return 1;
    }
    mosquitto_subscribe(sub, nullptr, topic.c_str(), 0);
    const auto limit = Clock::now() + std::chrono::duration<double>(c.seconds + 30);
    while (Clock::now() < limit) {
        if (c.started && std::chrono::duration<double>(Clock::now() - c.t0).count() >= c.seconds)
            break;
        const int rc = mosquitto_loop(sub, 50, 1);
        if (rc != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_NO_CONN) {
            fmt::print(stderr, "subscriber: {}\n", mosquitto_strerror(rc));
            return 1;
        }
    }
    const double elapsed =
        c.started ? std::chrono::duration<double>(Clock::now() - c.t0).count() : 0;
    json processes = json::object();
    for (const auto& w : c.watched) {
        const double cpu1 = cpu_seconds(w.pid);
        processes[w.name] = {
            {"pid", w.pid},
            {"cpu_pct", cpu1 < 0 || elapsed <= 0 ? -1 : 100.0 * (cpu1 - w.cpu0) / elapsed},
            {"rss_mib", rss_mib(w.pid)}};
    }
    mosquitto_disconnect(sub);
    mosquitto_destroy(sub);
    mosquitto_lib_cleanup();

    auto& l = c.latency_ms;
    std::sort(l.begin(), l.end());
    const auto pct = [&](double q) -> double {
        return l.empty() ? -1
                         : l[std::min(l.size() - 1,
                                      static_cast<std::size_t>(q * static_cast<double>(l.size())))];
    };
    // Whole seconds only: the last one is cut by the window's end.
    const std::size_t whole = std::min(c.per_second.size(), static_cast<std::size_t>(elapsed));
    const auto [lo, hi] =
        whole == 0 ? std::pair<std::uint64_t, std::uint64_t>{0, 0}
                   : std::pair{*std::min_element(c.per_second.begin(),
                                                 c.per_second.begin() + static_cast<long>(whole)),
                               *std::max_element(c.per_second.begin(),
                                                 c.per_second.begin() + static_cast<long>(whole))};
    std::uint32_t topic_lo = 0, topic_hi = 0;
    std::uint64_t repeats = 0;
    if (!c.per_topic.empty()) {
        topic_lo = UINT32_MAX;
        for (const auto& [name, t] : c.per_topic) {
            topic_lo = std::min(topic_lo, t.messages);
            topic_hi = std::max(topic_hi, t.messages);
            repeats += t.repeats;
        }
    }
    json stats = json::object();
    if (c.last_stats.is_object() && c.first_stats.is_object()) {
        const double span =
            static_cast<double>(counter_of(c.last_stats, "ts") - counter_of(c.first_stats, "ts")) /
            1000.0;
        stats = {{"span_s", span},
                 {"overruns",
                  counter_of(c.last_stats, "overruns") - counter_of(c.first_stats, "overruns")},
                 {"timeouts",
                  counter_of(c.last_stats, "timeouts") - counter_of(c.first_stats, "timeouts")},
                 {"values_polled_per_s",
                  span > 0 ? static_cast<double>(counter_of(c.last_stats, "values") -
                                                 counter_of(c.first_stats, "values")) /
                                 span
                           : 0.0}};
    }
    json out = {{"label", label},
                {"seconds", elapsed},
                {"values", c.values},
                {"values_per_s", elapsed > 0 ? static_cast<double>(c.values) / elapsed : 0.0},
                {"values_per_s_min", lo},
                {"values_per_s_max", hi},
                {"tag_errors", c.errors},
                {"messages", c.messages},
                {"malformed", c.malformed},
                {"topics", c.per_topic.size()},
                {"messages_per_topic_min", topic_lo},
                {"messages_per_topic_max", topic_hi},
                {"repeated_first_value", repeats},
                {"latency_ms",
                 {{"p50", pct(0.5)},
                  {"p99", pct(0.99)},
                  {"max", l.empty() ? -1.0 : static_cast<double>(l.back())}}},
                {"stats", stats},
                {"processes", processes}};
    fmt::print("{}\n", out.dump());
    return c.started ? 0 : 1;
}
