// CONVERT TO HOST LINK FINS COMMAND (W342 5-1-1 note 2, "Specifying the Destination
// PLC's FINS Address"; frames 6 "Any/any"): a FINS command for a PLC behind a gateway
// port (DNA = the port's network, DA1 = Host Link unit number + 1) goes out on the port
// as a Host Link FINS frame (network form, W342 3-5) and the PLC's answer comes back as
// the FINS response, later (docs/architecture.md "Deferred answers").
//
// Every answer comes from the address the sender asked (clients match on it).
// The frame on the line addresses the Host Link slave's own CPU Unit: DNA 00, DA1 00
// (local network, local PLC), DA2 as sent; the gateway count drops by one (a gateway
// was passed; 0 left: 0504 too many relays). The answer is rebuilt on the request's
// header, so the sender sees it from the address it asked.
//
// An answer on the line with another SID than the request's (a late answer to an earlier
// request) is not this request's: dropped and counted, the request keeps waiting for its
// own within the port's timeout (0205 if none comes). The answer passed back crosses the
// gateway as it would a router: its GCT is the slave's less one.
//
// End codes: DA1 outside 1-32: 0201; a session that cannot answer later: 0204; the
// port's 0204/0205/0206; an answer whose FCS is wrong or that does not decode: 0206;
// a Host Link end code from the slave: 13 (it saw a bad FCS) 0206, 18 (frame too
// long) 1001, 16 (not supported) 0401, any other 0206. These mappings are choices
// (W342 and W336 are silent on them), pinned in tests/integration.
#include <array>

#include "fins/host_link.hpp"
#include "server/handlers/handlers.hpp"
#include "server/serial/serial_ports.hpp"

namespace fins::server::handlers {

namespace {

constexpr std::uint8_t max_host_link_node = 32;  // unit numbers 0-31, plus one
constexpr std::size_t gateway_count_offset = 2;
constexpr std::size_t service_id_offset = 9;

// Is a Host Link frame from the line the answer to the request with this SID? Only a
// decodable normal answer names a SID; anything else is judged by the completion (0206,
// the end-code mappings above).
bool answers(Bytes line, std::uint8_t service_id) noexcept {
    std::array<std::uint8_t, host_link_max_fins_response> fins{};
    const auto decoded = decode_host_link(line, true, fins);
    if (!decoded || decoded->end_code != HostLinkEndCode::normal ||
        decoded->fins_size < header_size)
        return true;
    return fins[service_id_offset] == service_id;
}

EndCode end_code_for(HostLinkEndCode code) noexcept {
    switch (code) {
        case HostLinkEndCode::frame_length_error:
            return EndCode::command_too_long;
        case HostLinkEndCode::command_not_supported:
            return EndCode::undefined_command;
        default:
            return EndCode::transmission_error;
    }
}

}  // namespace

std::size_t relay_to_host_link(SerialGatewayPort& port, Bytes request, const Header& header,
                               const NodeAddress& self, MutableBytes out,
                               const RequestContext& context) {
    ByteReader reader(request.subspan(header_size));
    const CommandCode command{reader.u8(), reader.u8()};
    // Every answer, errors included, comes from the address the sender asked: clients
    // match answers by it (the port's own unit address would be dropped as foreign).
    (void)self;
    const Header from_plc = response_header(header, header.destination);
    const auto refuse = [&](EndCode code) -> std::size_t {
        if (!header.response_required()) return 0;
        ByteWriter w(out);
        write_response_prefix(w, from_plc, command, static_cast<std::uint16_t>(code));
        return w.overflowed() ? 0 : w.size();
    };
    const std::uint8_t node = header.destination.node;
    if (node == 0 || node > max_host_link_node)
        return refuse(EndCode::destination_node_not_in_network);
    if (header.gateway_count == 0) return refuse(EndCode::too_many_relays);
    if (context.reply_path == nullptr) return refuse(EndCode::destination_node_busy);

    std::array<std::uint8_t, max_frame_size> forwarded{};
    // The dispatcher refuses longer frames before any route (1001); this copy never
    // relies on it.
    if (request.size() > forwarded.size()) return refuse(EndCode::command_too_long);
    std::copy(request.begin(), request.end(), forwarded.begin());
    forwarded[gateway_count_offset] = static_cast<std::uint8_t>(header.gateway_count - 1);
    forwarded[3] = local_network;  // DNA
    forwarded[4] = 0x00;           // DA1: the local PLC
    const auto unit = static_cast<std::uint8_t>(node - 1);
    std::array<std::uint8_t, host_link_max_command_chars> line{};
    const auto size = encode_host_link_command(unit, 0, HostLinkForm::network,
                                               Bytes{forwarded.data(), request.size()}, line);
    if (!size) return refuse(EndCode::command_too_long);

    Completion reply;
    if (header.response_required()) reply = context.reply_path->defer();
    port.submit(
        SerialFraming::host_link, Bytes{line.data(), *size}, true,
        [reply = std::move(reply), from_plc, command, unit](EndCode end, Bytes payload) {
            if (!reply) return;
            std::array<std::uint8_t, max_frame_size> frame{};
            ByteWriter w(frame);
            std::array<std::uint8_t, host_link_max_fins_response> fins{};
            if (end == EndCode::normal_completion) {
                const auto decoded = decode_host_link(payload, true, fins);
                if (!decoded || decoded->unit != unit)
                    end = EndCode::transmission_error;
                else if (decoded->end_code != HostLinkEndCode::normal)
                    end = end_code_for(decoded->end_code);
                else if (decoded->fins_size < header_size + command_code_size)
                    end = EndCode::transmission_error;
                if (end == EndCode::normal_completion) {
                    // The answer crosses the gateway on its way back, as through a router
                    // (router.hpp): the slave's GCT less one.
                    Header answer = from_plc;
                    const std::uint8_t gateway_count = fins[gateway_count_offset];
                    answer.gateway_count =
                        static_cast<std::uint8_t>(gateway_count > 0 ? gateway_count - 1 : 0);
                    write_header(w, answer);
                    w.bytes(Bytes{fins.data() + header_size, decoded->fins_size - header_size});
                    reply(Bytes{frame.data(), w.size()});
                    return;
                }
            }
            write_response_prefix(w, from_plc, command, static_cast<std::uint16_t>(end));
            if (!w.overflowed()) reply(Bytes{frame.data(), w.size()});
        },
        [service_id = header.service_id](Bytes answer) { return answers(answer, service_id); });
    return 0;
}

}  // namespace fins::server::handlers
