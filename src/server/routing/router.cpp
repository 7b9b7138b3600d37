// Router: "is it for me" per port, and forwarding by the 8013 routing tables (see
// router.hpp for the rules and end codes).
#include "server/routing/router.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "transport/socket_headers.hpp"

#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/dispatch/relay_error.hpp"
#include "server/metrics/metrics.hpp"

namespace fins::server {

namespace {

constexpr std::size_t gateway_count_offset = 2;
constexpr std::size_t source_network_offset = 6;
constexpr std::uint32_t address_slots = 128 * 256;

std::uint32_t slot(std::uint8_t network, std::uint8_t node) noexcept {
    return static_cast<std::uint32_t>(((network & 0x7F) << 8) | node);
}

// The answer crosses this router on its way back: its GCT drops by one (not below 00).
void cross_back(MutableBytes answer) noexcept {
    if (answer.size() > gateway_count_offset && answer[gateway_count_offset] > 0)
        --answer[gateway_count_offset];
}

// A later answer (a Serial Gateway port's, dispatcher.hpp "ReplyPath") crosses this
// router as an answer on the call stack does. Lives on forward()'s stack: defer() is only
// called while the next node handles the frame.
class CrossingReplyPath final : public ReplyPath {
  public:
    explicit CrossingReplyPath(ReplyPath* outer) noexcept : outer_(outer) {}
    CrossingReplyPath(const CrossingReplyPath&) = delete;
    CrossingReplyPath& operator=(const CrossingReplyPath&) = delete;
    ~CrossingReplyPath() = default;

    Completion defer() override {
        return [reply = outer_->defer()](Bytes frame) {
            if (!reply) return;
            std::array<std::uint8_t, max_frame_size> answer{};
            const std::size_t n = std::min(frame.size(), answer.size());
            std::memcpy(answer.data(), frame.data(), n);
            cross_back(MutableBytes{answer.data(), n});
            reply(Bytes{answer.data(), n});
        };
    }

  private:
    ReplyPath* outer_;
};

}  // namespace

Router::Router() : by_address_(address_slots, 0) {}

std::size_t Router::add_cpu(plc::Plc& plc, bool nx) {
    cpus_.push_back(Cpu{&plc, nx, {}, 0, {}});
    return cpus_.size() - 1;
}

std::vector<std::pair<std::uint16_t, std::uint64_t>> Router::relay_counts(
    const plc::Plc& plc) const {
    std::vector<std::pair<std::uint16_t, std::uint64_t>> out;
    for (const auto& c : cpus_) {
        if (c.plc != &plc) continue;
        std::uint64_t refused = 0;
        for (const auto& [code, n] : c.relays_refused)
            refused += n;
        out.emplace_back(0x0000, c.relays_taken - refused);
        out.insert(out.end(), c.relays_refused.begin(), c.relays_refused.end());
    }
    return out;
}

std::size_t Router::add_port(std::size_t cpu, std::uint8_t unit_number, NodeAddress address) {
    const std::size_t index = ports_.size();
    ports_.push_back(Port{cpu, unit_number, address, nullptr, {}});
    cpus_[cpu].ports.push_back(index);
    by_address_[slot(address.network, address.node)] = static_cast<std::uint32_t>(index + 1);
    return index;
}

void Router::set_dispatcher(std::size_t port, Dispatcher& dispatcher) noexcept {
    ports_[port].dispatcher = &dispatcher;
}

void Router::set_addresses(std::size_t port, const NodeAddressTable& table) noexcept {
    ports_[port].addresses = table;
}

bool Router::note_source(std::size_t port, const Header& header,
                         const RequestContext& context) noexcept {
    if (context.peer == nullptr || context.peer->ss_family != AF_INET) return true;
    Port& arrival = ports_[port];
    const auto& source = header.source;
    if (source.network != local_network && source.network != arrival.address.network)
        return true;  // relayed: the answer goes back the way the frame came
    // SA1 00 is no remote node (fins-frames.md 1.3: 00 is "internal communications inside
    // the local PLC", nodes are 01-FE): the conversion (W596 2-3) has no entry for it, so
    // the answer goes where the request came from (fins-frames.md 2, "Reply destination"),
    // as a single node answers; nothing is learned (issue 26 point 14).
    if (source.node == 0) return true;
    sockaddr_in peer{};
    std::memcpy(&peer, context.peer, sizeof peer);
    Ipv4Endpoint from{{}, ntohs(peer.sin_port)};
    std::memcpy(from.ip.data(), &peer.sin_addr.s_addr, 4);
    arrival.addresses.learn(source.node, from);
    if (header.is_response()) return true;
    const auto to = arrival.addresses.lookup(source.node);
    if (!to) return false;
    if (*to == from) return true;
    peer.sin_port = htons(to->port);
    std::memcpy(&peer.sin_addr.s_addr, to->ip.data(), 4);
    std::memcpy(context.peer, &peer, sizeof peer);
    return true;
}

std::optional<std::size_t> Router::find_port(std::uint8_t network,
                                             std::uint8_t node) const noexcept {
    if (network > 0x7F) return std::nullopt;
    const auto index = by_address_[slot(network, node)];
    if (index == 0) return std::nullopt;
    return index - 1;
}

std::optional<NodeAddress> Router::local_address(std::size_t port,
                                                 const NodeAddress& destination) const noexcept {
    const Port& arrival = ports_[port];
    if (destination.network == local_network || destination.network == arrival.address.network)
        return arrival.address;
    for (const std::size_t other : cpus_[arrival.cpu].ports) {
        const auto& a = ports_[other].address;
        if (a.network != destination.network) continue;
        if (destination.node == 0 || destination.node == a.node) return a;
    }
    return std::nullopt;
}

std::uint8_t Router::network_for_local(std::size_t cpu) const noexcept {
    const auto& c = cpus_[cpu];
    if (c.ports.empty()) return local_network;
    if (c.nx) return ports_[c.ports.front()].address.network;
    const auto smallest = std::min_element(c.ports.begin(), c.ports.end(), [&](auto a, auto b) {
        return ports_[a].unit_number < ports_[b].unit_number;
    });
    return ports_[*smallest].address.network;
}

std::size_t Router::relay_error(const Header& request, CommandCode command, const Port& arrival,
                                EndCode code, MutableBytes out) const noexcept {
    metrics::note_relay_error(code);
    return write_relay_error(request, command, arrival.address, code, out);
}

std::size_t Router::forward(std::size_t port, Bytes frame, MutableBytes out,
                            const RequestContext& context) {
    // Without a header and command code there is no SID to answer (as the dispatcher).
    if (frame.size() < header_size + command_code_size) return 0;
    metrics::note_relay();
    ByteReader reader(frame);
    const Header header = read_header(reader);
    const CommandCode command{reader.u8(), reader.u8()};
    const Port& arrival = ports_[port];
    Cpu& cpu = cpus_[arrival.cpu];
    ++cpu.relays_taken;
    const auto fail = [&](EndCode code) {
        const auto key = static_cast<std::uint16_t>(code);
        const auto it = std::find_if(cpu.relays_refused.begin(), cpu.relays_refused.end(),
                                     [&](const auto& kv) { return kv.first == key; });
        if (it != cpu.relays_refused.end())
            ++it->second;
        else
            cpu.relays_refused.emplace_back(key, 1);  // a handful of end codes at most
        // An answer that cannot be delivered is not answered (there is no one to tell).
        if (header.is_response()) return std::size_t{0};
        return relay_error(header, command, arrival, code, out);
    };
    // Longer than a FINS frame (W596 1-2: 2,012 bytes): not passed on; 1001 as a node
    // answers it, from the router that received it.
    if (frame.size() > max_frame_size) return fail(EndCode::command_too_long);

    const auto decoded =
        plc::decode_routing_tables(cpu.plc->parameters().words(plc::routing_table_area));
    if (decoded.state == plc::RoutingTablesState::none) return fail(EndCode::no_routing_tables);
    if (decoded.state == plc::RoutingTablesState::broken) return fail(EndCode::routing_table_error);
    const auto& tables = decoded.tables;

    const std::uint8_t target = header.destination.network;
    std::uint8_t hop_network = target;
    std::uint8_t hop_node = header.destination.node;
    if (tables.find_local(target) == nullptr) {
        const auto* relay = tables.find_relay(target);
        if (relay == nullptr) return fail(EndCode::destination_address_setting_error);
        hop_network = relay->relay_network;
        hop_node = relay->relay_node;
    }
    // The local network table names the unit on the next hop's network: it must be a
    // port of this CPU Unit on that very network.
    const auto* local = tables.find_local(hop_network);
    const auto out_port = std::find_if(cpu.ports.begin(), cpu.ports.end(), [&](std::size_t p) {
        return ports_[p].unit_number == local->unit && ports_[p].address.network == hop_network;
    });
    if (out_port == cpu.ports.end()) return fail(EndCode::routing_table_error);
    // An answer is never refused for its GCT: it started from whatever the command had
    // left, and dropping it would only make the requester time out.
    if (header.gateway_count == 0 && !header.is_response()) return fail(EndCode::too_many_relays);

    std::array<std::uint8_t, max_frame_size> copy{};
    std::memcpy(copy.data(), frame.data(), frame.size());
    const std::uint8_t gateway_count = std::min(header.gateway_count, max_gateway_count);
    copy[gateway_count_offset] =
        static_cast<std::uint8_t>(gateway_count > 0 ? gateway_count - 1 : 0);
    if (header.source.network == local_network)
        copy[source_network_offset] = arrival.address.network;
    const Bytes relayed{copy.data(), frame.size()};

    if (hop_node == broadcast_node) return broadcast(arrival.cpu, hop_network, relayed, context);

    const auto next = find_port(hop_network, hop_node);
    if (!next) {
        if (wire_ && wire_(*out_port, hop_node, relayed)) return 0;
        return fail(EndCode::destination_node_not_in_network);
    }
    Dispatcher* dispatcher = ports_[*next].dispatcher;
    if (dispatcher == nullptr) return fail(EndCode::destination_node_not_in_network);
    // The hand-off is not a datagram: the next node learns no address from it.
    RequestContext inner = context;
    inner.peer = nullptr;
    // An answer now (on the call stack) or later (through the reply path) crosses this
    // router on its way back.
    CrossingReplyPath crossing(context.reply_path);
    if (context.reply_path != nullptr) inner.reply_path = &crossing;
    const std::size_t n = dispatcher->handle(relayed, out, inner);
    cross_back(out.first(n));
    return n;
}

std::size_t Router::broadcast(std::size_t cpu, std::uint8_t network, Bytes frame,
                              const RequestContext& context) {
    // Each node runs it as a broadcast on its own network; what it answers stays there.
    std::array<std::uint8_t, max_frame_size> discarded{};
    RequestContext inner = context;
    inner.peer = nullptr;
    inner.reply_path = nullptr;
    for (const Port& port : ports_) {
        if (port.address.network != network || port.cpu == cpu || port.dispatcher == nullptr)
            continue;
        (void)port.dispatcher->handle(frame, discarded, inner);
    }
    return 0;
}

}  // namespace fins::server
