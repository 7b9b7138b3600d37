// Runs the bridge until SIGINT/SIGTERM: the poller on one io_context, MQTT on its own
// thread (mqtt.hpp). Returns the process exit code (0 clean, 3 start-up failure).
#pragma once

#include <string>

#include "bridge/config.hpp"

namespace fins::bridge {

int run(const BridgeConfig& config, const std::string& log_level = "info");

}  // namespace fins::bridge
