// `fins probe`: which FINS node answers at HOST:PORT, and the --dest that reaches it.
//
// Over UDP the client addresses node "host's last octet" (1 at 127.0.0.1), so a PLC set to
// another node answers 0201. A request to node 00 means "the local node" (W342 5-1-1
// DA1), which a PLC answers with its own address in the response's source field: one
// 05 01 CPU UNIT DATA READ sent that way tells the node and the model. Over TCP the
// FINS/TCP handshake reports the server's node.
#include <array>
#include <chrono>
#include <string>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "cli/fins/udp_socket.hpp"
#include "fins/commands/access_right.hpp"
#include "fins/commands/configuration.hpp"
#include "fins/frame.hpp"

namespace fins::cli {

namespace {

constexpr std::uint8_t probe_service_id = 0x5A;
// Node 254 unless the local address gives a better one: a PLC converting node numbers
// to IP addresses (automatic generation) answers to its network's host SA1.
constexpr std::uint8_t probe_source_node = 254;

std::uint8_t local_node(const UdpSocket& socket) {
    const auto local = socket.local_v4();
    if (!local) return probe_source_node;
    const auto first = *local >> 24;
    const auto last = *local & 0xFF;
    if (first == 127 || last == 0 || last == 255) return probe_source_node;
    return static_cast<std::uint8_t>(last);
}

Result<FoundNode> discover_udp(const GlobalOptions& g) {
    UdpSocket s;
    if (auto ec = s.connect(g.host, g.port)) return Unexpected(ec);

    Header h;
    h.destination = NodeAddress{0, 0, 0};
    h.source = NodeAddress{0, local_node(s), 0};
    if (auto src = parse_node_address(g.source); src && !g.source.empty()) h.source = *src;
    const NodeAddress source = h.source;
    h.service_id = probe_service_id;
    std::array<std::uint8_t, 64> frame{};
    const auto size = encode_request(h, CpuUnitDataRead::code, Bytes{}, frame);
    if (!size) return Unexpected(size.error());

    const auto wait = std::chrono::milliseconds(static_cast<long>(g.timeout_seconds * 1000.0));
    for (unsigned attempt = 0; attempt <= g.retries; ++attempt) {
        if (auto ec = s.send({frame.data(), *size})) return Unexpected(ec);
        const auto deadline = std::chrono::steady_clock::now() + wait;
        // Bounded: every turn either returns or moves towards the deadline.
        while (true) {
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                deadline - std::chrono::steady_clock::now());
            if (left.count() <= 0) break;
            std::array<std::uint8_t, 2048> in{};
            // ICMP port unreachable: nothing listens there, as `fins read` says too.
            const auto n = s.receive(in, left);
            if (!n) return Unexpected(n.error());
            if (*n == 0) break;  // nothing by the deadline (an empty datagram is not FINS)
            auto r = decode_response(Bytes(in.data(), *n));
            if (!r || r->header.service_id != probe_service_id ||
                r->command != CpuUnitDataRead::code)
                continue;
            FoundNode node{r->header.source, source, {}};
            node.address.unit = 0;
            if (r->code.ok())
                if (auto data = CpuUnitDataRead{}.decode_response(r->data))
                    node.model = data->model;
            return node;
        }
    }
    return Unexpected(make_error_code(ClientError::timeout));
}

Result<FoundNode> discover_tcp(const GlobalOptions& g) {
    ClientOptions o;
    o.host = g.host;
    o.port = g.port;
    o.protocol = ClientOptions::Protocol::tcp;
    o.timeout = std::chrono::milliseconds(static_cast<long>(g.timeout_seconds * 1000.0 + 0.5));
    if (!g.source.empty())
        if (auto src = parse_node_address(g.source)) o.source = *src;
    auto client = Client::connect(o);
    if (!client) return Unexpected(client.error());
    FoundNode node{(*client)->destination(), (*client)->source(), {}};
    if (auto data = (*client)->send(CpuUnitDataRead{CpuUnitDataSection::model_and_area}))
        node.model = data->model;
    return node;
}

// Host Link: the PLC on the line answers its CPU Unit data (there is no node to find).
Result<FoundNode> discover_serial(const GlobalOptions& g) {
    int rc = 0;
    Output quiet{false};
    auto client = open_client(g, quiet, rc);
    if (!client) return Unexpected(make_error_code(ClientError::not_connected));
    auto data = client->send(CpuUnitDataRead{CpuUnitDataSection::model_and_area});
    if (!data) return Unexpected(data.error());
    return FoundNode{client->destination(), client->source(), data->model};
}

// --dest given: ask that node (through the routing tables of the nodes on the way, as any
// request goes) and report who answered.
Result<FoundNode> ask_dest(const GlobalOptions& g, Output& out, int& rc) {
    auto client = open_client(g, out, rc);
    if (!client) return Unexpected(std::error_code{});
    const CpuUnitDataRead command{CpuUnitDataSection::model_and_area};
    std::array<std::uint8_t, 8> parameters{};
    ByteWriter w(parameters);
    command.encode(w);
    auto r = client->send_raw(CpuUnitDataRead::code, w.written());
    if (!r) return Unexpected(r.error());
    if (r->code.relay_error()) out.note_relay(r->relay);
    if (!r->code.ok()) return Unexpected(make_error_code(r->code.end_code()));
    FoundNode node{r->header.source, client->source(), {}};
    if (auto data = command.decode_response(r->data)) node.model = data->model;
    return node;
}

const char* link_name(const GlobalOptions& g) {
    return !g.serial.empty() ? "Host Link" : g.tcp ? "TCP" : "UDP";
}

}  // namespace

std::optional<std::uint8_t> read_dip_switch(const GlobalOptions& g) {
    int rc = 0;
    Output quiet{false};
    auto client = open_client(g, quiet, rc);
    if (!client) return std::nullopt;
    auto data = client->send(CpuUnitDataRead{CpuUnitDataSection::model_and_area});
    if (!data) return std::nullopt;
    return data->dip_switch;
}

std::optional<NodeAddress> access_right_holder(const GlobalOptions& g) {
    int rc = 0;
    Output quiet{false};
    auto client = open_client(g, quiet, rc);
    if (!client) return std::nullopt;
    std::array<std::uint8_t, 2> buffer{};
    ByteWriter w(buffer);
    AccessRightAcquire{}.encode(w);
    auto r = client->send_raw(AccessRightAcquire::code, w.written());
    if (!r) return std::nullopt;
    // Free again since the refusal: give it back at once, as found.
    if (r->code.ok()) {
        (void)client->send(AccessRightRelease{});
        return std::nullopt;
    }
    if (r->code.end_code() != EndCode::no_access_right) return std::nullopt;
    auto holder = AccessRightHolder::decode(r->data);
    if (!holder) return std::nullopt;
    return holder->holder;
}

std::string access_right_hint(const NodeAddress& holder) {
    const auto node = node_text(holder);
    return fmt::format(
        "node {} holds the access right (0C 01): `fins access force` takes it over (0C 02), "
        "or the holder gives it back (`fins --source {} access release` sends its 0C 03)",
        node, node);
}

Result<FoundNode> discover_node(const GlobalOptions& g) {
    if (!g.serial.empty()) return discover_serial(g);
    return g.tcp ? discover_tcp(g) : discover_udp(g);
}

int run_probe(const GlobalOptions& g, Output& out) {
    const std::string context = fmt::format("probe {} over {}", endpoint(g), link_name(g));
    if (const auto bad = check_node_options(g)) return out.usage(*bad);
    int rc = exit_ok;
    const bool dest_given = !g.dest.empty();
    auto found = dest_given ? ask_dest(g, out, rc) : discover_node(g);
    if (!found) return rc != exit_ok ? rc : out.failure(found.error(), context);
    // The node a plain `fins` would address: the client's own derivation, no request sent.
    GlobalOptions plain = g;
    plain.dest.clear();
    std::optional<NodeAddress> derived;
    if (!g.tcp && g.serial.empty() && !dest_given) {
        Output quiet{false};
        if (auto c = open_client(plain, quiet, rc)) derived = c->destination();
    }
    const bool needs_dest = derived && derived->node != found->address.node;
    nlohmann::json doc{{"host", g.host},
                       {"port", g.port},
                       {"protocol", !g.serial.empty() ? "hostlink"
                                    : g.tcp           ? "tcp"
                                                      : "udp"},
                       {"node", node_text(found->address)},
                       {"local_node", node_text(found->local)},
                       {"model", found->model},
                       {"needs_dest", needs_dest}};
    std::string text =
        fmt::format("{} over {}: FINS node {}{}\n", endpoint(g), link_name(g),
                    node_text(found->address), found->model.empty() ? "" : ", " + found->model);
    if (needs_dest)
        text += fmt::format("fins addresses node {} here by default: add --dest {}\n",
                            derived->node, node_text(found->address));
    // What a network write protection list must name to let this client write (W342
    // 5-1-2): over UDP the local address's node (254 on loopback), over TCP the node the
    // handshake allocated for this connection (docs/cli.md, "Which source node fins uses").
    if (g.serial.empty())
        text += fmt::format("fins sends as node {}{}\n", node_text(found->local),
                            !g.source.empty() ? " (--source)"
                            : g.tcp           ? " (allocated by the FINS/TCP handshake)"
                                              : " (from the local address; 254 on loopback)");
    out.print(doc, text);
    return exit_ok;
}

}  // namespace fins::cli
