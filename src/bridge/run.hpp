// Runs the bridge until SIGINT/SIGTERM: the pollers and MQTT (mqtt.hpp) on one io_context,
// on one thread. Returns the process exit code (0 clean, 3 start-up failure).
#pragma once

#include <string>

#include "bridge/config.hpp"

namespace fins::bridge {

int run(const BridgeConfig& config, const std::string& log_level = "info");

}  // namespace fins::bridge
