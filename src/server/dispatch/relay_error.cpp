// write_relay_error (see relay_error.hpp).
#include "server/dispatch/relay_error.hpp"

namespace fins::server {

std::size_t write_relay_error(const Header& request, CommandCode command, const NodeAddress& relay,
                              EndCode code, MutableBytes out) noexcept {
    if (!request.response_required()) return 0;
    Header response = response_header(request, request.destination);
    response.gateway_count = default_gateway_count;
    ByteWriter w(out);
    write_response_prefix(w, response, command,
                          static_cast<std::uint16_t>(static_cast<std::uint16_t>(code) |
                                                     ResponseCode::relay_error_bit));
    w.u8(relay.network);
    w.u8(relay.node);
    return w.overflowed() ? 0 : w.size();
}

}  // namespace fins::server
