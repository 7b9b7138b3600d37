// PLC-initiated messages (W596 section 3): the node runs Send (write words to a remote
// node: 01 02), Rcv (read words from a remote node: 01 01) and SendCmd (any command),
// as a CPU Unit's network instructions do, from its own port and FINS address.
//
// One engine per node, owned by whatever owns the node's sessions (server.cpp). It has
// no socket of its own: frames leave through an InstructionTransport (the node's UDP
// socket, port 9600 as configured; a fake in unit tests) and responses come back
// through on_response(), which the node's UDP session calls for every frame whose ICF
// response bit is set (udp_session.cpp) instead of handing it to the dispatcher.
//
// An answer is the instruction's only when it comes back the way the command went
// (issue 18 item 6): FINS/UDP from the address and port the node address table gives
// for that node, FINS/TCP on the connection the command was put on; and its header
// names the destination's network, node and unit as source and this node as
// destination. Any other process can send a datagram to port 9600: a forged answer
// is counted as unmatched and the instruction goes on waiting (then retries, 0205).
//
// One engine with fins::Client (issue 27): the instructions run on the client's
// RequestTracker (engine/request_tracker.hpp, W596 3 Send/Rcv/SendCmd "Option"), one per
// node, each request with its own destination, this node as source and the port as
// tag. It keeps the SIDs, timeouts and retries: a retry resends the identical frame with
// the same SID; a SID whose instruction got no answer to some transmission (timed out or
// retried) is quarantined for twice that instruction's timeout, clean SIDs are reused
// least recently used first, so a late answer to an ended instruction never completes a
// later one (it is counted as unmatched). When every free SID is quarantined (more than
// 224 late answers pending) an instruction waits for one, its port busy, its clock not
// started. A frame the transport refuses (no route, no port, connection not established,
// or the kernel refused the last attempt) ends only that instruction and quarantines
// nothing: it never left. This class keeps what is the node's own: ports and flags,
// parameters, the frames' contents, the way an answer must come back (below), results.
//
// W596 3 parameters and limits:
//   destination network 0-127, node 0-254 (255 = broadcast: Send/SendCmd only, no
//   response), unit 00-FF; words 0-990 (0: Done without sending); timeout in 0.1 s
//   units, 0 = 2.0 s; retries 0-15; no-response mode (ICF bit 0; Rcv refuses it);
//   at most 32 instructions at once.
// Completion (W596 3 "Error, ErrorID, ErrorIDEx"): ErrorID 0000 Done; 0400 a parameter
// is out of range (nothing is sent); 0800 communications: ErrorIDEx holds the FINS end
// code (W596: "the end code for the communication command"): the response's end code
// when it is not normal, 0205 response timeout after the last retry, 0104 when 32
// instructions are already running (the 33rd), 0501 no IP address for that network or
// node, 0101 the node has no FINS/UDP port or its FINS/TCP connection is not
// established (W596 3 Send error g, Rcv j, SendCmd h), 0103 the frame could not be sent.
// docs/networks.md "PLC-initiated messages" lists them.
//
// CS/CJ profiles also show the instruction ports in the Auxiliary Area as their CPU
// Units do: A202 bits 0-7 Communications Port Enabled Flags (ON = port free), A203-A210
// Communications Port Completion Codes, A219 bits 0-7 Communications Port Error Flags.
// An instruction takes the lowest free port (0-31); ports 0-7 have flags.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "engine/request_tracker.hpp"
#include "fins/address.hpp"
#include "fins/frame.hpp"
#include "server/instructions/instruction_parameters.hpp"
#include "transport/asio.hpp"

namespace fins::plc {
class Plc;
class IoMemory;
}  // namespace fins::plc

namespace fins::server {

struct InstructionResult {
    std::uint16_t error_id = instruction_done;
    std::uint16_t error_id_ex = 0;          // the FINS end code when error_id is 0800
    std::optional<std::uint16_t> end_code;  // the response's end code word, when one came
    int port = -1;                          // the port used; -1: none (parameter error ...)
    unsigned transmissions = 0;             // frames sent (1 + retries used)
    std::vector<std::uint8_t> response;     // SendCmd: MRC SRC MRES SRES data
    std::vector<std::uint16_t> words;       // Rcv: the words stored
    std::string detail;                     // why, in words
    [[nodiscard]] bool done() const noexcept { return error_id == instruction_done; }
};

using InstructionCallback = std::function<void(const InstructionResult&)>;

// The way a frame went out, so the way its answer must come back.
struct InstructionRoute {
    asio::ip::udp::endpoint udp;       // FINS/UDP: the remote node's address and port
    const void* connection = nullptr;  // FINS/TCP: the connection (null: FINS/UDP)
    // This node's FINS node number on that way (a FINS/TCP client's is the one its
    // handshake gave it); 0: this node's own.
    std::uint8_t local_node = 0;
    // Same way: same connection, or (FINS/UDP) same address and port.
    [[nodiscard]] bool same_way(const InstructionRoute& other) const noexcept {
        return connection == other.connection && (connection != nullptr || udp == other.udp);
    }
};

// Where an instruction's frames go.
class InstructionTransport {
  public:
    // ok; no_route: no IP address for that network/node; no_port: the node has no
    // FINS/UDP port; not_established: the node is reached over a FINS/TCP client
    // connection ([[remote]] transport = "tcp") that is down; failed: the kernel
    // refused the frame.
    enum class Sent : std::uint8_t { ok, no_route, no_port, not_established, failed };
    virtual ~InstructionTransport() = default;
    // Sends `frame` to `destination`; on ok, `route` says which way it went.
    virtual Sent send_frame(const NodeAddress& destination, Bytes frame,
                            InstructionRoute& route) = 0;
    // No answer came in time to a frame that went by `route` (each transmission that
    // timed out, retries included). A FINS/TCP client connection counts them.
    virtual void unanswered(const InstructionRoute& route) { (void)route; }
};

class NetworkInstructions {
  public:
    struct Counters {
        std::uint64_t started = 0;
        std::uint64_t done = 0;
        std::uint64_t errors = 0;
        std::uint64_t timeouts = 0;         // instructions that ended with 0205
        std::uint64_t retransmissions = 0;  // frames sent again after a timeout
        std::uint64_t unmatched = 0;        // responses no instruction waited for
    };

    NetworkInstructions(asio::any_io_executor executor, plc::Plc& plc, NodeAddress self,
                        InstructionTransport& transport);
    ~NetworkInstructions();
    NetworkInstructions(const NetworkInstructions&) = delete;
    NetworkInstructions& operator=(const NetworkInstructions&) = delete;

    // Runs `request`; `done` is called once, later, on the executor (never inside start).
    void start(InstructionRequest request, InstructionCallback done);
    // A frame with the ICF response bit set that arrived at the node by `from`. True
    // when it was the answer an instruction waited for (and came back the way the
    // command went); false leaves it to the caller (dropped).
    bool on_response(Bytes frame, const InstructionRoute& from);
    // Ends every running instruction without calling back (shutdown).
    void stop();

    [[nodiscard]] std::size_t in_flight() const noexcept { return in_flight_; }
    // _Port_isAvailable: a port is free.
    [[nodiscard]] bool available() const noexcept { return in_flight_ < max_instructions; }
    [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
    [[nodiscard]] const NodeAddress& self() const noexcept { return self_; }

  private:
    struct Port;
    // The tracker, its sink (the transport), its answer check (the route) and its timer.
    struct Link;
    // The tracker's completion of port `index`'s request.
    void on_answer(std::size_t port, Result<ResponseView> answer);
    // The result of a response that matched port `index`'s request.
    InstructionResult result_of(std::size_t port, const ResponseView& view);
    void finish(std::size_t port, InstructionResult result);
    void complete_later(InstructionCallback done, InstructionResult result);
    void show_port(std::size_t port, bool busy, std::optional<std::uint16_t> completion);

    asio::any_io_executor executor_;
    plc::Plc& plc_;
    NodeAddress self_;
    InstructionTransport& transport_;
    std::vector<std::unique_ptr<Port>> ports_;
    std::size_t in_flight_ = 0;
    // Made on first use, like the ports (its request slots are made as needed too).
    std::unique_ptr<Link> link_;
    bool flags_ = false;  // the profile shows ports in A202/A203-A210/A219
    Counters counters_;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fins::server
