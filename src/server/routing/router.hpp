// The router of a plant: several CPU Units, each with one or more Communications Units
// ("ports": a unit number on a FINS network at a node), in one process. A CPU Unit with
// ports on two networks is a router (W596 2-4, frames-networks section 2).
//
// Where it sits: every port's Dispatcher asks local_address() "is this frame for my CPU
// Unit?" (the single destination check, dispatcher.cpp). When it is not, the Dispatcher
// hands the frame to forward(), which routes it by the CPU Unit's routing tables, read
// from parameter area 8013 at every frame (plc/routing_tables.hpp: 02 02 changes routing
// at once):
//   destination network in the local network table -> the port with that unit number,
//     next node = DA1;
//   in the relay network table -> the port on the relay network, next node = relay node;
//   the frame is copied with GCT - 1 (SNA 00 becomes the arrival network, so answers
//     find their way back), and handed to the next node's Dispatcher (a node of this
//     process) or sent as a datagram to it (another process, router_wire.cpp);
//   faults answer with the relay flag (end code bit 15) and the relay word naming the
//     network and node of this router on the arrival side (W342 5-1-3):
//       0502 no routing tables, 0503 broken tables or a table naming a unit that is not
//       mounted, 0501 a network in neither table, 0504 GCT already 00 (too many relays),
//       0201 the next node is not reachable (no address known for it).
//   a broadcast (DA1 FF, fins-frames.md 1.3) for a network in the local network table
//     is relayed as a broadcast on that network: every other CPU Unit of this process
//     with a unit on it runs the command; their answers are not passed back (one
//     request, many answers; a broadcast goes without one, W343 08 03), so the requester
//     gets none. Nodes in other processes do not get it (the loopback plant has no
//     broadcast address).
// An answer from a node of this process comes back on the call stack, the reverse route,
// with its GCT decremented at each router it crosses.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/routing/node_address_table.hpp"

namespace fins::plc {
class Plc;
}

namespace fins::server {

// Hops a frame may still make: GCT values above 07 are taken as 07 (CS/CJ ver. 2.0+
// cross at most 8 network levels, W393 1-6), which also bounds the in-process call depth.
inline constexpr std::uint8_t max_gateway_count = 0x07;

class Router {
  public:
    struct Port {
        std::size_t cpu = 0;
        std::uint8_t unit_number = 0;  // 00-0F
        NodeAddress address;           // network, node, unit 00
        Dispatcher* dispatcher = nullptr;
        NodeAddressTable addresses;  // FINS/UDP: where frames for each node go
    };

    // Sends a frame to a node outside this process through `port`; false when the port
    // knows no address for `node` (the caller answers 0201). Set by the plant.
    using WireSend = std::function<bool(std::size_t port, std::uint8_t node, Bytes frame)>;

    Router();

    // Registers a CPU Unit; returns its index.
    std::size_t add_cpu(plc::Plc& plc, bool nx);
    // Registers a port of `cpu`; returns its index (the Dispatcher's attach() takes it).
    std::size_t add_port(std::size_t cpu, std::uint8_t unit_number, NodeAddress address);
    void set_dispatcher(std::size_t port, Dispatcher& dispatcher) noexcept;
    void set_addresses(std::size_t port, const NodeAddressTable& table) noexcept;

    // A frame arrived on `port` (FINS/UDP: from context.peer). When its source is on the
    // port's network, the node-address table learns it (as the method allows) and the
    // answer is sent where the table says (context.peer is rewritten). False when the
    // table knows no address for the source node: the command runs, nothing is answered
    // (a real unit cannot send to 0.0.0.0). A source node 00 (SA1 = 0) has no entry: it
    // is answered at context.peer under every method.
    bool note_source(std::size_t port, const Header& header,
                     const RequestContext& context) noexcept;
    void set_wire(WireSend send) { wire_ = std::move(send); }

    // The address this CPU Unit answers as when `destination` (as received on `port`) is
    // for it: DNA 00 or the arrival network (the Dispatcher then checks DA1, 0201 as
    // today), or another port's network with DA1 00 or that port's node. nullopt: the
    // frame is for another node and goes to forward().
    [[nodiscard]] std::optional<NodeAddress> local_address(
        std::size_t port, const NodeAddress& destination) const noexcept;

    // Routes a frame received on `port` that is not for this CPU Unit. Writes the answer
    // to send back on `port` into `out` (a relay error, or the answer of a node of this
    // process) and returns its length; 0 when none is due now.
    std::size_t forward(std::size_t port, Bytes frame, MutableBytes out,
                        const RequestContext& context);

    // the network DNA 00 means in a frame this CPU Unit starts: NX, the built-in
    // port (the first); CS/CJ, the network of the Communications Unit with the smallest
    // unit number.
    [[nodiscard]] std::uint8_t network_for_local(std::size_t cpu) const noexcept;

    // The port of this process at (network, node), if any.
    [[nodiscard]] std::optional<std::size_t> find_port(std::uint8_t network,
                                                       std::uint8_t node) const noexcept;
    [[nodiscard]] const Port& port(std::size_t index) const noexcept { return ports_[index]; }
    [[nodiscard]] std::size_t port_count() const noexcept { return ports_.size(); }
    // The frames `plc`'s ports handed to forward(), by end code: 0000 passed on (or
    // answered by a node of this process), else the relay error it was refused with.
    // Empty when `plc` is not a CPU Unit of this router.
    [[nodiscard]] std::vector<std::pair<std::uint16_t, std::uint64_t>> relay_counts(
        const plc::Plc& plc) const;

  private:
    struct Cpu {
        plc::Plc* plc = nullptr;
        bool nx = false;
        std::vector<std::size_t> ports;
        std::uint64_t relays_taken = 0;
        std::vector<std::pair<std::uint16_t, std::uint64_t>> relays_refused;  // by end code
    };

    std::size_t relay_error(const Header& request, CommandCode command, const Port& arrival,
                            EndCode code, MutableBytes out) const noexcept;
    // A broadcast (DA1 FF) for a network of the local network table, from `cpu`: handed
    // to the unit of every other CPU Unit of this process on `network`; no answer comes
    // back (returns 0).
    std::size_t broadcast(std::size_t cpu, std::uint8_t network, Bytes frame,
                          const RequestContext& context);

    std::vector<Cpu> cpus_;
    std::vector<Port> ports_;
    // (network << 8 | node) -> port index + 1; 0 = not in this process.
    std::vector<std::uint32_t> by_address_;
    WireSend wire_;
};

}  // namespace fins::server
