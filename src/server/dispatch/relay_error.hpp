// A relay error answer (W342 5-1-3): the end code with bit 15 set and the relay word, the
// network and node of the unit that failed to pass the frame on, on the side the frame
// came from. Written by the one unit that finds the fault: a plant router (router.hpp)
// or this node's front stage for a frame it will not pass on (dispatcher.cpp).
#pragma once

#include <cstddef>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins::server {

// The answer names the node the command was sent to as its source, so the requester
// matches it with its request; GCT starts again at the default. Returns its length, 0
// when no answer is asked for (ICF bit 0) or `out` is too small.
std::size_t write_relay_error(const Header& request, CommandCode command, const NodeAddress& relay,
                              EndCode code, MutableBytes out) noexcept;

}  // namespace fins::server
