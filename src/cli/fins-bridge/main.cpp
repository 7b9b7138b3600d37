// fins-bridge: polls Omron PLCs over FINS and publishes their tags to MQTT, and writes
// setpoints back (docs/bridge.md).
//
//   fins-bridge --config FILE [--instance NAME]   run
//   fins-bridge --config FILE --plan              print the frames each group is read with
//
// Exit codes: 0 clean shutdown (SIGINT/SIGTERM), 2 usage or configuration error
// ("file:line:col: message"), 3 start-up failure.
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "bridge/config.hpp"
#include "bridge/poll/plan.hpp"
#include "bridge/run.hpp"

int main(int argc, char** argv) {
    CLI::App app{"fins-bridge: Omron PLC tags over FINS to MQTT and back (docs/bridge.md)"};
    // As fins and finsd: options are --name on every system.
    app.allow_windows_style_options(false);
    std::string config;
    std::string instance;
    bool plan = false;
    std::string log_level = "info";
    app.add_option("--config", config, "TOML configuration file")->required();
    app.add_option("--instance", instance, "instance name (default: [bridge] instance, host name)");
    app.add_flag("--plan", plan, "print the frames each group is read with, then exit");
    app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
    app.set_version_flag("--version", std::string("fins-bridge ") + FINSKIT_VERSION);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    auto c = fins::bridge::load_config(config, instance);
    if (!c) {
        fmt::print(stderr, "fins-bridge: {}\n", c.error());
        return 2;
    }
    if (plan) {
        for (const auto& p : c->plcs)
            for (const auto& g : p.groups) {
                const auto pl = fins::bridge::plan_group(g.tags, g.gap_words);
                fmt::print("{}/{}: {} tags, {} frames every {} ms\n", p.name, g.name, g.tags.size(),
                           pl.frames.size(), g.interval.count());
                std::string text = fins::bridge::describe_plan(pl, g.tags);
                std::size_t at = 0;
                while (at < text.size()) {
                    const auto nl = text.find('\n', at);
                    fmt::print("  {}\n", text.substr(at, nl - at));
                    at = nl + 1;
                }
            }
        return 0;
    }
    return fins::bridge::run(*c, log_level);
}
