#include "bridge/run.hpp"

#include <csignal>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>

#include "bridge/bridge.hpp"
#include "bridge/json_payload.hpp"

namespace fins::bridge {

std::unique_ptr<PayloadFormat> make_format(const BridgeConfig& config) {
    // "sparkplug" plugs in here (payload.hpp); until then JSON.
    return std::make_unique<JsonPayload>(config.mqtt.topic_prefix, config.instance);
}

int run(const BridgeConfig& config, const std::string& log_level) {
    spdlog::set_default_logger(spdlog::stderr_color_mt("fins-bridge"));
    spdlog::set_level(spdlog::level::from_str(log_level));
    asio::io_context io(1);
    Bridge bridge(io, config, make_format(config), std::make_unique<SingleInstance>());
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
    return 0;
}

}  // namespace fins::bridge
