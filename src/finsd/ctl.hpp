// `finsd ctl ...`: the client side of the control channel (server/control/control.hpp).
// main() calls run_ctl when the first argument is "ctl"; argv starts at "ctl".
#pragma once

namespace fins::finsd {

int run_ctl(int argc, char** argv);

}  // namespace fins::finsd
