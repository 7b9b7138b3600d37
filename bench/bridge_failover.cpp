// fins_bridge_failover: how long the PLCs of a fins-bridge instance killed with SIGKILL go
// unpublished before another instance takes them over (docs/benchmarks.md "fins-bridge
// failover"). Real parts: mosquitto, finsd, N fins-bridge processes sharing one config.
// Each round: start everything, wait until every PLC publishes, kill -9 one instance (or,
// with --freeze, SIGSTOP it: a silent death only the keep-alive reveals), and
// measure, for each PLC that instance owned, the gap between its last data message before the
// kill and its first one after. The gap is bounded by failover_s (the broker publishes the
// Will 1.5 x keepalive after the last packet) plus one poll interval.
#include <algorithm>
#include <cstdio>
#include <regex>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "bridge/cluster/processes.hpp"
#include "bridge/cluster/rendezvous.hpp"

namespace tb = fins::test::bridge;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

std::uint16_t finsd_port(const tb::Child& p) {
    const std::regex listening("listening ([0-9]+)");
    for (int i = 0; i < 200; ++i) {
        std::smatch m;
        const auto log = p.log();
        if (std::regex_search(log, m, listening))
            return static_cast<std::uint16_t>(std::stoi(m[1]));
        std::this_thread::sleep_for(20ms);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins-bridge failover time after kill -9"};
    int rounds = 3;
    int instances = 2;
    int plcs = 20;
    int failover_s = 10;
    int interval_ms = 100;
    bool freeze = false;
    bool keep = false;
    app.add_option("--rounds", rounds)->check(CLI::Range(1, 100));
    app.add_option("--instances", instances)->check(CLI::Range(2, 8));
    app.add_option("--plcs", plcs)->check(CLI::Range(1, 1000));
    app.add_option("--failover", failover_s, "failover_s of the config")->check(CLI::Range(1, 600));
    app.add_option("--interval", interval_ms, "poll interval (ms)")->check(CLI::Range(10, 10000));
    app.add_flag("--freeze", freeze,
                 "SIGSTOP instead of SIGKILL: the socket stays open and silent (a hung host or "
                 "a lost network), so the broker learns of the death only from the keep-alive");
    app.add_flag("--keep", keep, "keep the logs (printed directory)");
    CLI11_PARSE(app, argc, argv);
    if (tb::mosquitto_path().empty()) {
        std::fprintf(stderr, "mosquitto is not installed\n");
        return 1;
    }
    const auto dir =
        std::filesystem::temp_directory_path() / fmt::format("finskit-failover-{}", ::getpid());
    std::filesystem::create_directories(dir);
    std::vector<double> worst;
    for (int round = 0; round < rounds; ++round) {
        const auto rdir = dir / fmt::format("round{}", round + 1);
        std::filesystem::create_directories(rdir);
        tb::Mosquitto broker(rdir);
        tb::Child finsd({tb::finsd_exe, "--port", "0", "--log-level", "warn"}, rdir / "finsd.log");
        const auto port = finsd_port(finsd);
        if (!broker.started() || port == 0) {
            std::fprintf(stderr, "mosquitto or finsd did not start\n");
            return 1;
        }
        std::string conf = fmt::format(
            "[bridge]\nfailover_s = {}\n[mqtt]\nhost = \"127.0.0.1\"\nport = {}\n"
            "topic_prefix = \"fo\"\n",
            failover_s, broker.port());
        for (int i = 0; i < plcs; ++i)
            conf += fmt::format(
                "[[plc]]\nname = \"p{}\"\nhost = \"127.0.0.1\"\nport = {}\n[[plc.group]]\nname = "
                "\"g\"\n"
                "interval_ms = {}\npublish = \"always\"\ntags = [ {{ name = \"v\", address = "
                "\"D{}\", type = \"int16\" }} ]\n",
                i, port, interval_ms, i);
        const auto conf_path = rdir / "bridge.toml";
        std::ofstream(conf_path) << conf;
        tb::Recorder rec(broker.port(), std::vector<std::string>{"fo/+/g"});
        std::vector<std::string> names;
        std::vector<std::unique_ptr<tb::Child>> bridges;
        for (int i = 0; i < instances; ++i) {
            names.push_back(fmt::format("i{}", i));
            bridges.push_back(std::make_unique<tb::Child>(
                std::vector<std::string>{tb::bridge_path, "--config", conf_path.string(),
                                         "--instance", names.back()},
                rdir / (names.back() + ".log")));
        }
        // (Inside Recorder::wait, which holds its lock: use the messages it hands in.)
        auto published_since = [&](const std::vector<tb::Received>& ms, Clock::time_point t) {
            std::set<std::string> seen;
            for (const auto& m : ms)
                if (m.at >= t) seen.insert(m.topic);
            return static_cast<int>(seen.size()) == plcs;
        };
        const auto started = Clock::now();
        if (!rec.wait([&](const auto& ms) { return published_since(ms, started); }, 60s)) {
            std::fprintf(stderr, "not every PLC published\n");
            return 1;
        }
        std::this_thread::sleep_for(2s);
        const auto victim = static_cast<std::size_t>(round) % names.size();
        std::vector<std::string> moved;
        for (int i = 0; i < plcs; ++i)
            if (fins::bridge::cluster::rendezvous_owner(names, fmt::format("p{}", i)) == victim)
                moved.push_back(fmt::format("fo/p{}/g", i));
        if (freeze)
            ::kill(bridges[victim]->pid(), SIGSTOP);
        else
            bridges[victim]->kill(SIGKILL);
        const auto killed = Clock::now();
        rec.wait(
            [&](const auto& ms) {
                std::set<std::string> back;
                for (const auto& m : ms)
                    if (m.at > killed + 50ms) back.insert(m.topic);
                return std::all_of(moved.begin(), moved.end(),
                                   [&](const auto& t) { return back.count(t) > 0; });
            },
            std::chrono::seconds(failover_s * 4 + 10));
        double round_worst = 0;
        const auto ms = rec.messages();
        for (const auto& topic : moved) {
            Clock::time_point last_before{}, first_after{};
            for (const auto& m : ms) {
                if (m.topic != topic) continue;
                if (m.at <= killed) last_before = m.at;
                if (m.at > killed + 50ms && first_after == Clock::time_point{}) first_after = m.at;
            }
            if (first_after == Clock::time_point{}) {
                round_worst = -1;
                break;
            }
            round_worst = std::max(
                round_worst, std::chrono::duration<double>(first_after - last_before).count());
        }
        if (freeze) bridges[victim]->kill(SIGKILL);
        std::printf("round %d: %s %s owning %zu of %d PLCs, longest gap %.2f s\n", round + 1,
                    freeze ? "froze" : "killed", names[victim].c_str(), moved.size(), plcs,
                    round_worst);
        std::fflush(stdout);
        worst.push_back(round_worst);
    }
    std::sort(worst.begin(), worst.end());
    std::printf(
        "failover_s %d, %d instances, %d PLCs at %d ms: longest gap min %.2f s, median %.2f s, max "
        "%.2f s\n",
        failover_s, instances, plcs, interval_ms, worst.front(), worst[worst.size() / 2],
        worst.back());
    if (keep)
        std::printf("logs in %s\n", dir.c_str());
    else
        std::filesystem::remove_all(dir);
    return 0;
}
