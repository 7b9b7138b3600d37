#include "bridge/run.hpp"

#include <fmt/format.h>

namespace fins::bridge {

int run(const BridgeConfig& config) {
    fmt::print(stderr, "fins-bridge: {} PLCs configured; the runtime is not built yet\n",
               config.plcs.size());
    return 3;
}

}  // namespace fins::bridge
