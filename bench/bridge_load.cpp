// fins_bridge_load: fins-bridge against a finsd plant of --plcs CPU Units with --tags tags
// each (mixed types, 20 of them scattered), polled every --interval-ms, publishing to a
// local mosquitto; a subscriber checks every value it receives against what was written
// (docs/benchmarks.md "fins-bridge"). A writer changes one int16 tag in one PLC every
// millisecond (round robin over PLCs and tags) by FINS, and the latency from the write's
// answer to the value's arrival at the subscriber is measured. Reported: tag values
// polled per second and overruns (the bridge's own stats topic), messages received,
// mismatches, the bridge's CPU and RSS, latency p50/p99.
//
//   build/bin/fins_bridge_load [--plcs 1000] [--tags 100] [--interval-ms 100] [--seconds 20]
#include <arpa/inet.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bridge/bridge_processes.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "integration/support/process.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

std::string unit_ip(std::size_t i) {
    return fmt::format("127.0.{}.{}", 40 + i / 250, 1 + i % 250);
}

// CPU seconds (user + system) of a process.
double cpu_seconds(pid_t pid) {
    std::ifstream f(fmt::format("/proc/{}/stat", pid));
    std::string s((std::istreambuf_iterator<char>(f)), {});
    const auto close = s.rfind(')');
    if (close == std::string::npos) return 0;
    std::istringstream rest(s.substr(close + 2));
    std::string field;
    unsigned long utime = 0, stime = 0;
    for (int i = 3; i <= 15 && rest >> field; ++i) {
        if (i == 14) utime = std::stoul(field);
        if (i == 15) stime = std::stoul(field);
    }
    return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

long status_kib(pid_t pid, const std::string& key) {
    std::ifstream f(fmt::format("/proc/{}/status", pid));
    for (std::string line; std::getline(f, line);)
        if (line.rfind(key, 0) == 0) return std::stol(line.substr(key.size()));
    return -1;
}

struct Written {
    int value = 0;
    int previous = 0;
    Clock::time_point at{};
    bool measured = true;
};

struct Model {
    std::mutex mutex;
    std::map<std::pair<std::size_t, int>, Written> written;  // (plc, tag index) -> last writes
    std::vector<double> latencies_ms;
    std::uint64_t messages = 0;
    std::uint64_t values = 0;
    std::uint64_t mismatches = 0;
    std::uint64_t errors = 0;
    std::vector<json> stats;
};

// Tag k of every PLC: 0-39 int16 D0-D39, 40-59 float D40.., 60-69 int32 D80.., 70-79 bool
// CIO0.00-0.09, 80-99 int16 scattered D1000, D1100 ... (01 04).
std::string tag_list(std::size_t tags) {
    std::string out;
    for (std::size_t k = 0; k < tags; ++k) {
        std::string address, type;
        if (k < 40) {
            address = fmt::format("D{}", k), type = "int16";
        } else if (k < 60) {
            address = fmt::format("D{}", 40 + 2 * (k - 40)), type = "float";
        } else if (k < 70) {
            address = fmt::format("D{}", 80 + 2 * (k - 60)), type = "int32";
        } else if (k < 80) {
            address = fmt::format("CIO0.{:02}", k - 70), type = "bool";
        } else {
            address = fmt::format("D{}", 1000 + 100 * (k - 80)), type = "int16";
        }
        out += fmt::format("{}{{name=\"t{}\",address=\"{}\",type=\"{}\"}}", k ? ",\n  " : "", k,
                           address, type);
    }
    return out;
}

// The PLC word of writable tag k (int16 tags only).
std::uint16_t word_of(int k) {
    return static_cast<std::uint16_t>(k < 40 ? k : 1000 + 100 * (k - 80));
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_bridge_load: fins-bridge against a finsd plant and a local mosquitto"};
    std::size_t plcs = 1000;
    std::size_t tags = 100;
    int interval_ms = 100;
    double seconds = 20;
    int writes_per_s = 1000;
    std::string bin = FINS_BIN_DIR;
    app.add_option("--plcs", plcs, "CPU Units in the plant (at most 1000)");
    app.add_option("--tags", tags, "tags per PLC (at most 100)");
    app.add_option("--interval-ms", interval_ms, "group interval");
    app.add_option("--seconds", seconds, "measurement time after a 5 s warm-up");
    app.add_option("--writes-per-s", writes_per_s, "FINS writes of a changed value per second");
    app.add_option("--bin", bin, "directory of finsd and fins-bridge");
    CLI11_PARSE(app, argc, argv);
    plcs = std::min<std::size_t>(plcs, 1000);
    tags = std::min<std::size_t>(tags, 100);

    const auto dir =
        std::filesystem::temp_directory_path() / fmt::format("fins-bridge-load-{}", ::getpid());
    std::filesystem::create_directories(dir);
    const std::uint16_t plc_port = 9650;

    std::string plant = "log_level = \"warn\"\n";
    for (std::size_t i = 0; i < plcs; ++i)
        plant += fmt::format(
            "[[plc]]\nname = \"p{}\"\n  [[plc.ethernet]]\n  unit = 0\n  network = {}\n"
            "  bind = \"{}\"\n  port = {}\n",
            i, 1 + i / 250, unit_ip(i), plc_port);
    std::ofstream(dir / "plant.toml") << plant;
    // Children log to files: a pipe nobody reads would block them once full.
    fins::test::Child finsd(
        {bin + "/finsd", "--config", (dir / "plant.toml").string(), "--log-level", "warn"},
        dir / "finsd.log");
    if (!finsd.wait_for_stderr("listening", std::chrono::seconds(30))) {
        fmt::print(stderr, "finsd did not start: {}\n", finsd.wait(std::chrono::seconds(5)).err);
        return 1;
    }

    // The tests' broker (bridge_processes.hpp), with room for the whole run's messages.
    fins::test::bridge::Mosquitto broker(dir, "max_queued_messages 100000\n");
    if (!broker.started()) {
        fmt::print(stderr, "mosquitto did not start (log in {})\n", dir.string());
        return 1;
    }
    const std::uint16_t mqtt_port = broker.port();

    Model model;
    mosquitto_lib_init();
    mosquitto* sub = mosquitto_new(nullptr, true, &model);
    mosquitto_message_callback_set(sub, [](mosquitto*, void* p, const mosquitto_message* m) {
        auto& md = *static_cast<Model*>(p);
        const auto now = Clock::now();
        std::string topic(m->topic);
        auto j = json::parse(static_cast<const char*>(m->payload),
                             static_cast<const char*>(m->payload) + m->payloadlen, nullptr, false);
        std::lock_guard lock(md.mutex);
        if (topic.find("/$bridge/") != std::string::npos) {
            if (topic.ends_with("/stats")) md.stats.push_back(j);
            return;
        }
        if (!topic.ends_with("/g")) return;
        ++md.messages;
        const auto slash = topic.find('/');
        const std::size_t plc = std::stoul(topic.substr(slash + 2, topic.rfind('/') - slash - 2));
        for (auto& [name, v] : j["values"].items()) {
            ++md.values;
            if (v.is_object()) {
                ++md.errors;
                continue;
            }
            const int k = std::stoi(name.substr(1));
            auto it = md.written.find({plc, k});
            const double expect = it == md.written.end() ? 0 : it->second.value;
            const double got = v.is_boolean() ? (v.get<bool>() ? 1 : 0) : v.get<double>();
            if (got == expect) {
                if (it != md.written.end() && !it->second.measured) {
                    it->second.measured = true;
                    md.latencies_ms.push_back(
                        std::chrono::duration<double, std::milli>(now - it->second.at).count());
                }
            } else if (it == md.written.end() || got != it->second.previous) {
                ++md.mismatches;
            }
        }
    });
    if (mosquitto_connect(sub, "127.0.0.1", mqtt_port, 60) != MOSQ_ERR_SUCCESS) {
        fmt::print(stderr, "cannot connect to mosquitto on {}\n", mqtt_port);
        return 1;
    }
    mosquitto_subscribe(sub, nullptr, "load/#", 0);
    mosquitto_loop_start(sub);

    std::string config = fmt::format(
        "[bridge]\nstats_s = 2\n[mqtt]\nhost = \"127.0.0.1\"\nport = {}\ntopic_prefix = \"load\"\n"
        "queue_limit = 100000\n",
        mqtt_port);
    const std::string group = fmt::format(
        "[[plc.group]]\nname = \"g\"\ninterval_ms = {}\npublish = \"change\"\ntags = [\n  {}]\n",
        interval_ms, tag_list(tags));
    for (std::size_t i = 0; i < plcs; ++i)
        config +=
            fmt::format("[[plc]]\nname = \"p{}\"\nhost = \"{}\"\nport = {}\ndest = \"0.{}.0\"\n{}",
                        i, unit_ip(i), plc_port, 1 + i % 250, group);
    std::ofstream(dir / "bridge.toml") << config;
    fins::test::Child bridge({bin + "/fins-bridge", "--config", (dir / "bridge.toml").string(),
                              "--instance", "load", "--log-level", "warn"},
                             dir / "bridge.log");

    // The writer: one UDP socket, MEMORY AREA WRITE of one word, waits for the answer.
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    timeval tv{0, 200000};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    std::atomic<bool> writing{true};
    std::uint64_t writes = 0;
    std::vector<int> next_value(plcs * 100, 0);
    std::thread writer([&] {
        std::this_thread::sleep_for(std::chrono::seconds(3));
        const std::vector<int> writable = [&] {
            std::vector<int> w;
            for (int k = 0; k < static_cast<int>(tags); ++k)
                if (k < 40 || k >= 80) w.push_back(k);
            return w;
        }();
        std::size_t n = 0;
        auto next = Clock::now();
        const auto period = std::chrono::microseconds(1000000 / std::max(writes_per_s, 1));
        while (writing) {
            next += period;
            std::this_thread::sleep_until(next);
            const std::size_t plc = n % plcs;
            const int k = writable[(n / plcs) % writable.size()];
            ++n;
            const int value = (next_value[plc * 100 + static_cast<std::size_t>(k)] % 30000) + 1;
            next_value[plc * 100 + static_cast<std::size_t>(k)] = value;
            const std::uint16_t word = static_cast<std::uint16_t>(value);
            std::array<std::uint8_t, 2> data{static_cast<std::uint8_t>(word >> 8),
                                             static_cast<std::uint8_t>(word)};
            std::array<std::uint8_t, 64> params{};
            fins::ByteWriter w(params);
            fins::MemoryAreaWrite{{0x82, word_of(k), 0}, 1, data}.encode(w);
            fins::Header h;
            h.destination = {0, static_cast<std::uint8_t>(1 + plc % 250), 0};
            h.source = {0, 254, 0};
            h.service_id = static_cast<std::uint8_t>(n);
            std::array<std::uint8_t, 128> frame{};
            auto size = fins::encode_request(h, fins::MemoryAreaWrite::code, w.written(), frame);
            sockaddr_in a{};
            a.sin_family = AF_INET;
            a.sin_port = htons(plc_port);
            ::inet_pton(AF_INET, unit_ip(plc).c_str(), &a.sin_addr);
            {
                std::lock_guard lock(model.mutex);
                auto& wr = model.written[{plc, k}];
                wr.previous = wr.value;
                wr.value = value;
                wr.measured = true;  // not before the answer
            }
            ::sendto(fd, frame.data(), *size, 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
            std::array<std::uint8_t, 64> answer{};
            if (::recv(fd, answer.data(), answer.size(), 0) > 0) {
                std::lock_guard lock(model.mutex);
                auto& wr = model.written[{plc, k}];
                wr.at = Clock::now();
                wr.measured = false;
                ++writes;
            }
        }
    });

    std::this_thread::sleep_for(std::chrono::seconds(5));
    const pid_t pid = bridge.pid();
    const double cpu0 = cpu_seconds(pid);
    const double finsd0 = cpu_seconds(finsd.pid());
    const double broker0 = cpu_seconds(broker.pid());
    const auto t0 = Clock::now();
    std::size_t stats0 = 0;
    std::uint64_t messages0 = 0;
    {
        std::lock_guard lock(model.mutex);
        stats0 = model.stats.size();
        messages0 = model.messages;
        model.latencies_ms.clear();
        model.mismatches = 0;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    const double cpu1 = cpu_seconds(pid);
    const double finsd1 = cpu_seconds(finsd.pid());
    const double broker1 = cpu_seconds(broker.pid());
    const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    const long rss = status_kib(pid, "VmRSS:");
    const long hwm = status_kib(pid, "VmHWM:");
    writing = false;
    writer.join();
    // The subscriber stops before the model is read: its callback takes model.mutex, and
    // mosquitto_loop_stop() waits for that callback, so stopping it while holding the mutex
    // (as this did) waited forever for a callback that waited for the mutex. DISCONNECT ends
    // the loop thread after the callback in progress; the join is then bounded.
    mosquitto_disconnect(sub);
    mosquitto_loop_stop(sub, false);

    std::lock_guard lock(model.mutex);  // no other thread is left: for the analyser
    double values_per_s = 0;
    std::uint64_t overruns = 0, timeouts = 0, dropped = 0, published = 0;
    if (model.stats.size() > stats0 + 1) {
        const auto& a = model.stats[stats0];
        const auto& b = model.stats.back();
        const double dt =
            static_cast<double>(b["ts"].get<std::int64_t>() - a["ts"].get<std::int64_t>()) / 1000.0;
        values_per_s = static_cast<double>(b["values"].get<std::uint64_t>() -
                                           a["values"].get<std::uint64_t>()) /
                       dt;
        overruns = b["overruns"].get<std::uint64_t>() - a["overruns"].get<std::uint64_t>();
        timeouts = b["timeouts"].get<std::uint64_t>();
        dropped = b["dropped"].get<std::uint64_t>();
        published = b["published"].get<std::uint64_t>();
    }
    auto& l = model.latencies_ms;
    std::sort(l.begin(), l.end());
    const auto pct = [&](double p) {
        return l.empty() ? 0.0
                         : l[std::min(l.size() - 1,
                                      static_cast<std::size_t>(p * static_cast<double>(l.size())))];
    };
    fmt::print("plcs {} x tags {} every {} ms, {:.0f} s measured\n", plcs, tags, interval_ms,
               elapsed);
    fmt::print("values polled/s       {:.0f}\n", values_per_s);
    fmt::print("overruns              {} (in the window)\n", overruns);
    fmt::print("frame timeouts        {} (since start)\n", timeouts);
    fmt::print("messages published    {} (since start; dropped {})\n", published, dropped);
    fmt::print("messages received     {} in the window ({:.0f}/s), values {} total, errors {}\n",
               model.messages - messages0,
               static_cast<double>(model.messages - messages0) / elapsed, model.values,
               model.errors);
    fmt::print("mismatches            {}\n", model.mismatches);
    fmt::print("writes                {} ({} latency samples)\n", writes, l.size());
    fmt::print("latency write->sub    p50 {:.1f} ms  p99 {:.1f} ms  max {:.1f} ms\n", pct(0.5),
               pct(0.99), l.empty() ? 0.0 : l.back());
    fmt::print("bridge CPU            {:.1f} % of one core\n", 100.0 * (cpu1 - cpu0) / elapsed);
    fmt::print("finsd plant CPU       {:.1f} %, mosquitto CPU {:.1f} %\n",
               100.0 * (finsd1 - finsd0) / elapsed, 100.0 * (broker1 - broker0) / elapsed);
    fmt::print("bridge RSS            {:.1f} MiB (peak {:.1f} MiB)\n",
               static_cast<double>(rss) / 1024.0, static_cast<double>(hwm) / 1024.0);
    mosquitto_destroy(sub);
    mosquitto_lib_cleanup();
    bridge.terminate(SIGTERM);
    bridge.wait(std::chrono::seconds(10));
    finsd.terminate(SIGTERM);
    finsd.wait(std::chrono::seconds(20));
    std::filesystem::remove_all(dir);
    return 0;
}
