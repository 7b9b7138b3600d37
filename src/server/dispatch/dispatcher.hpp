// The pure request handler: one FINS request frame in, at most one response frame out.
// No sockets and no clock of its own (the caller passes `now`), so it is unit-tested
// directly and fuzzed. Sessions (udp_server, tcp_server) only read, call, write.
//
// Path of a request, the stages of handle() in order, each answering its own end code:
//   1. length: over 2,012 bytes (W596 1-2) -> 1001, before any route (relay error
//      9001 + relay word when the frame is for another node, W342 5-1-3);
//   2. destination: another node -> the plant's router (router.hpp) or the Host Link
//      relay (handlers/host_link_relay.cpp); this node -> is the unit there (0201, 0202);
//   3. command: the codec (10xx, 11xx), the command table and who serves it (0401);
//   4. execution conditions of W342 5-1-2;
//   5. the command's handler (src/server/handlers/<group>.cpp) -> response frame.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>

#include "fins/byte_io.hpp"
#include "fins/command_table.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "transport/socket_headers.hpp"

namespace fins::plc {
class Plc;
}

namespace fins::server {

class Router;
class SerialGatewayPort;
class FaultHook;

namespace handlers {
struct HandlerEntry;
}

// serial: the CPU Unit's Host Link port (server/serial/serial_session.hpp).
enum class Link : std::uint8_t { udp, tcp, local, serial };

// W342 5-1-2 note 5: network write protection covers commands "sent to CPU Units via
// networks"; in-process requests and the directly connected Host Link port are not.
constexpr bool via_network(Link link) noexcept {
    return link == Link::udp || link == Link::tcp;
}

class SerialPorts;

// Sends one response frame later, to where its request came from; a no-op once the
// session is gone. Called at most once, on the I/O thread.
using Completion = std::function<void(Bytes response_frame)>;

// The session's way back for an answer that is not ready when handle() returns (a
// Serial Gateway port's, docs/architecture.md "Deferred answers"). Only that path calls
// defer(); the synchronous path never touches it and allocates nothing.
class ReplyPath {
  public:
    // A completion bound to the request being handled now.
    virtual Completion defer() = 0;

  protected:
    ~ReplyPath() = default;
};

// What the session knows about where a request came from.
struct RequestContext {
    Link link = Link::udp;
    std::chrono::system_clock::time_point now{};
    ReplyPath* reply_path = nullptr;  // nullptr: this session cannot answer later
    // FINS/UDP: the datagram's source, where the answer goes. In a plant the port's
    // node-address table may learn from it and redirect the answer (router.hpp).
    sockaddr_storage* peer = nullptr;
};

class Dispatcher {
  public:
    // `self` is this node's address on the network (network, node, unit 00).
    Dispatcher(plc::Plc& plc, NodeAddress self) noexcept;

    // Handles one request frame. Writes the response frame into `out` (which must hold
    // max_frame_size bytes) and returns its length, or 0 when nothing is to be sent:
    // the ICF no-response bit was set, the frame is itself a response, or it is too
    // short to carry a header and command code (there is no SID to answer), or the
    // answer comes later through context.reply_path (a Serial Gateway port's).
    std::size_t handle(Bytes request, MutableBytes out, const RequestContext& context);

    // The Serial Gateway ports (nullptr: none); they outlive the dispatcher's use.
    void attach_serial_ports(SerialPorts* ports) noexcept { serial_ = ports; }
    [[nodiscard]] SerialPorts* serial_ports() const noexcept { return serial_; }

    [[nodiscard]] const NodeAddress& self() const noexcept { return self_; }
    plc::Plc& plc() noexcept { return plc_; }

    // In a plant (router.hpp) this dispatcher serves port `port` of a CPU Unit: the
    // router decides whether a frame is for this CPU Unit (any of its ports) and forwards
    // the others. Without a router only `self` is "me" (the single-node finsd).
    void attach(Router& router, std::size_t port) noexcept;
    // A scenario's unit faults (server/scenario/fault_hook.hpp); null: none.
    void attach_faults(FaultHook* faults) noexcept { faults_ = faults; }
    [[nodiscard]] FaultHook* faults() const noexcept { return faults_; }

  private:
    enum class Route : std::uint8_t { this_node, router, host_link };
    struct Destination {
        Route route = Route::this_node;
        NodeAddress self;                        // the address this node answers as
        SerialGatewayPort* host_link = nullptr;  // Route::host_link: the port
    };
    // The answer of this node to one request: the response header and the end-code
    // flags of the CPU Unit once the request reached it.
    struct Reply {
        Reply(plc::Plc& cpu_unit, const Header& request, CommandCode command_code,
              const NodeAddress& self, bool deliverable, MutableBytes out_buffer) noexcept;
        // Writes the response prefix with `code`; its length, 0 when none is wanted.
        [[nodiscard]] std::size_t answer(EndCode code) const noexcept;

        plc::Plc& plc;
        const Header& header;
        Header response;
        CommandCode command;
        bool wanted;
        bool cpu_reached = false;
        MutableBytes out;
    };

    [[nodiscard]] Destination find_destination(const Header& header) const noexcept;
    std::size_t refuse_too_long(const Header& header, CommandCode command, const Destination& to,
                                bool deliverable, MutableBytes out) noexcept;
    std::size_t run(Reply& reply, const CommandInfo& info, const handlers::HandlerEntry& entry,
                    Bytes parameters, const RequestContext& context);
    std::size_t run_with_faults(Reply& reply, const CommandInfo& info,
                                const handlers::HandlerEntry& entry, Bytes parameters,
                                const RequestContext& context);

    plc::Plc& plc_;
    NodeAddress self_;
    SerialPorts* serial_ = nullptr;
    Router* router_ = nullptr;
    std::size_t port_ = 0;
    FaultHook* faults_ = nullptr;
};

}  // namespace fins::server
