#include "server/sessions/tcp_node_table.hpp"

#include "fins/tcp.hpp"

namespace fins::server {

namespace {

// Auto-assigned client nodes: CS/CJ Ethernet units hand out 239-254 to FINS/TCP clients
// by default (one per connection); we fall back to the rest of 1-254 when those are taken.
constexpr std::uint8_t first_auto_node = 239;

}  // namespace

Result<std::uint8_t> TcpNodeTable::claim(std::uint8_t requested, TcpSession* owner) noexcept {
    if (requested > max_client_node)
        return Unexpected(make_error_code(TcpError::client_node_out_of_range));
    if (full()) return Unexpected(make_error_code(TcpError::all_connections_in_use));
    std::uint8_t node = requested;
    if (requested == 0) {
        auto free = [&](unsigned n) { return n != server_node_ && owners_[n] == nullptr; };
        node = 0;
        for (unsigned n = first_auto_node; n <= max_client_node && node == 0; ++n)
            if (free(n)) node = static_cast<std::uint8_t>(n);
        for (unsigned n = 1; n < first_auto_node && node == 0; ++n)
            if (free(n)) node = static_cast<std::uint8_t>(n);
        if (node == 0) return Unexpected(make_error_code(TcpError::no_node_available));
    } else if (requested == server_node_) {
        return Unexpected(make_error_code(TcpError::same_node_as_server));
    } else if (owners_[requested] != nullptr) {
        return Unexpected(make_error_code(TcpError::node_already_connected));
    }
    owners_[node] = owner;
    ++count_;
    return node;
}

void TcpNodeTable::release(std::uint8_t node, const TcpSession* owner) noexcept {
    if (node != 0 && owners_[node] != nullptr && owners_[node] == owner) {
        owners_[node] = nullptr;
        --count_;
    }
}

}  // namespace fins::server
