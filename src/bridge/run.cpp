#include "bridge/run.hpp"

#include <csignal>
#include <cstdio>
#include <cstdlib>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>

#include "bridge/bridge.hpp"
#include "bridge/cluster/cluster_ownership.hpp"
#include "bridge/json_payload.hpp"
#include "bridge/sparkplug/sparkplug_payload.hpp"

namespace fins::bridge {

std::unique_ptr<PayloadFormat> make_format(const BridgeConfig& config) {
    if (config.payload == "sparkplug")
        return std::make_unique<sparkplug::SparkplugPayload>(config, config.sparkplug_group);
    return std::make_unique<JsonPayload>(config.mqtt.topic_prefix, config.instance);
}

int run(const BridgeConfig& given, const std::string& log_level) {
    spdlog::set_default_logger(spdlog::stderr_color_mt("fins-bridge"));
    spdlog::set_level(spdlog::level::from_str(log_level));
    // Several instances share the PLCs (docs/bridge.md "Several instances"): the broker
    // announces a dead one through its Will 1.5 x keepalive after its last packet, so the
    // keepalive is cut to what failover_s needs.
    BridgeConfig config = given;
    const auto needed = std::chrono::seconds(
        cluster::keepalive_for_failover(static_cast<int>(config.failover.count())));
    if (config.mqtt.keepalive > needed) config.mqtt.keepalive = needed;
    asio::io_context io(1);
    Bridge bridge(io, config, make_format(config),
                  std::make_unique<cluster::ClusterOwnership>(
                      config.instance, config.mqtt.topic_prefix, config.payload));
    std::string error;
    if (!bridge.start(error)) {
        spdlog::error("{}", error);
        return 3;
    }
    asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](boost::system::error_code ec, int) {
        if (ec) return;
        bridge.stop();
        io.stop();
    });
    spdlog::info("fins-bridge {} polling {} PLCs", config.instance, config.plcs.size());
    io.run();
    bridge.stop();
    if (bridge.looking_up()) {
        // The goodbye is done. What is left is a broker name's lookup that a DNS server does
        // not answer: the io_context's destructor would wait for it (the system resolver's
        // own timeout, up to 30 s per attempt). Nothing else is pending: end here.
        spdlog::warn("fins-bridge: not waiting for the lookup of a broker's name");
        spdlog::shutdown();
        std::fflush(nullptr);
        std::_Exit(0);
    }
    return 0;
}

}  // namespace fins::bridge
