#include "transport/transport.hpp"

#include "fins/node_address.hpp"

namespace fins::transport {

std::uint8_t node_from_address(const asio::ip::address& address) noexcept {
    if (address.is_v4()) return node_from_ip(address.to_v4().to_bytes());
    return node_from_ip(address.to_v6().to_bytes());
}

}  // namespace fins::transport
