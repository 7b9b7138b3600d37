#include "transport/transport.hpp"

namespace fins::transport {

std::uint8_t node_from_address(const asio::ip::address& address) noexcept {
    if (address.is_loopback()) return 1;
    if (address.is_v4()) return address.to_v4().to_bytes()[3];
    auto v6 = address.to_v6();
    if (v6.is_v4_mapped()) {
        if (asio::ip::make_address_v4(asio::ip::v4_mapped, v6).is_loopback()) return 1;
    }
    return v6.to_bytes()[15];
}

}  // namespace fins::transport
