// NetworkInstructions: Send, Rcv and SendCmd (network_instructions.hpp, W596 3).
#include "server/instructions/network_instructions.hpp"

#include <algorithm>
#include <iterator>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

#include "engine/request_tracker.hpp"  // default_timeout, default_quarantine_timeouts
#include "fins/commands/memory_area.hpp"
#include "plc/plc.hpp"
#include "server/metrics/metrics.hpp"
#include "transport/asio.hpp"

namespace fins::server {

namespace {

// A202: Communications Port Enabled Flags; A203-A210: Completion Codes; A219: Error Flags.
constexpr std::size_t a_port_enabled = 202;
constexpr std::size_t a_completion_first = 203;
constexpr std::size_t a_port_error = 219;
constexpr std::size_t flagged_ports = 8;

InstructionResult parameter_error(std::string why) {
    InstructionResult r;
    r.error_id = instruction_parameter_error;
    r.detail = std::move(why);
    return r;
}

InstructionResult communications_error(EndCode code, std::string why) {
    InstructionResult r;
    r.error_id = instruction_communications_error;
    r.error_id_ex = static_cast<std::uint16_t>(code);
    r.detail = std::move(why);
    return r;
}

}  // namespace
// One instruction port: its request, frame and retry timer (allocated on first use, then
// kept).
struct NetworkInstructions::Port {
    explicit Port(const asio::any_io_executor& ex) : timer(ex) {}
    bool busy = false;
    InstructionRequest request;
    InstructionCallback done;
    std::array<std::uint8_t, max_frame_size> frame{};
    std::size_t frame_size = 0;
    std::uint8_t sid = 0;
    CommandCode command;
    InstructionRoute route;  // the way the last transmission went
    unsigned transmissions = 0;
    bool answered = false;  // an answer matched (its SID needs no quarantine)
    std::uint64_t generation = 0;
    asio::steady_timer timer;
};

NetworkInstructions::NetworkInstructions(asio::any_io_executor executor, plc::Plc& plc,
                                         NodeAddress self, InstructionTransport& transport)
    : executor_(std::move(executor)), plc_(plc), self_(self), transport_(transport) {
    // Ports are made on first use (start()): a plant of 1,000 CPU Units that never sends
    // would otherwise keep 32 ports of 2 KB frames resident in each (74 KB per unit).
    ports_.reserve(max_instructions);
    const auto& profile = plc_.profile();
    flags_ = !profile.nx_fixed_values && profile.auxiliary_words > a_port_error;
    for (std::size_t i = 0; i < flagged_ports; ++i)
        show_port(i, false, std::nullopt);
}

NetworkInstructions::~NetworkInstructions() {
    stop();
}

void NetworkInstructions::stop() {
    *alive_ = false;
    alive_ = std::make_shared<bool>(true);
    for (auto& p : ports_) {
        p->timer.cancel();
        if (p->busy) release_sid(*p, false);
        p->busy = false;
        p->done = nullptr;
    }
    in_flight_ = 0;
}

void NetworkInstructions::release_sid(Port& p, bool answered) {
    const auto unanswered = p.transmissions - (answered && p.transmissions > 0 ? 1U : 0U);
    // Twice the instruction's own timeout (fins::Client: default_quarantine_timeouts).
    sids_->set_quarantine(instruction_timeout(p.request.options.timeout) *
                          default_quarantine_timeouts);
    sids_->release(p.sid, unanswered, std::chrono::steady_clock::now());
}

void NetworkInstructions::complete_later(InstructionCallback done, InstructionResult result) {
    if (!done) return;
    asio::post(executor_, [done = std::move(done), result = std::move(result)] { done(result); });
}

void NetworkInstructions::start(InstructionRequest request, InstructionCallback done) {
    ++counters_.started;
    if (auto why = check_instruction(request, plc_.memory())) {
        ++counters_.errors;
        return complete_later(std::move(done), parameter_error(std::move(*why)));
    }
    const bool empty =
        request.kind == InstructionKind::sendcmd ? request.command.empty() : request.count == 0;
    if (empty) {  // W596: size 0 sends nothing and ends Done.
        ++counters_.done;
        InstructionResult r;
        r.detail = "nothing to send (size 0)";
        return complete_later(std::move(done), std::move(r));
    }
    auto free = std::find_if(ports_.begin(), ports_.end(), [](auto& p) { return !p->busy; });
    // Every port made so far is busy: the next one (the lowest free index, as when all 32
    // existed from the start), up to W596's 32.
    if (free == ports_.end() && ports_.size() < max_instructions) {
        ports_.push_back(std::make_unique<Port>(executor_));
        free = std::prev(ports_.end());
    }
    if (free == ports_.end()) {
        ++counters_.errors;
        return complete_later(std::move(done),
                              communications_error(EndCode::too_many_send_frames,
                                                   "32 instructions are already running"));
    }
    if (!sids_) sids_ = std::make_unique<SidPool>(default_timeout * default_quarantine_timeouts);
    const auto sid = sids_->acquire(std::chrono::steady_clock::now());
    if (!sid) {  // every free SID is quarantined (more than 224 late answers pending)
        ++counters_.errors;
        return complete_later(std::move(done),
                              communications_error(EndCode::too_many_send_frames,
                                                   "no service ID free (quarantined)"));
    }
    const auto index = static_cast<std::size_t>(free - ports_.begin());
    Port& p = **free;
    p.busy = true;
    p.done = std::move(done);
    p.transmissions = 0;
    p.sid = *sid;
    ++in_flight_;
    show_port(index, true, std::nullopt);

    // The frame, once: retries send the same bytes with the same SID.
    Header h;
    const bool broadcast = request.destination.node == broadcast_node;
    if (request.options.no_response || broadcast) h.icf |= icf_no_response;
    h.destination = request.destination;
    h.source = NodeAddress{self_.network, self_.node, cpu_unit};
    h.service_id = p.sid;
    ByteWriter w{MutableBytes{p.frame.data(), p.frame.size()}};
    write_header(w, h);
    if (request.kind == InstructionKind::sendcmd) {
        p.command = CommandCode{request.command[0], request.command[1]};
        w.bytes(Bytes{request.command.data(), request.command.size()});
    } else if (request.kind == InstructionKind::send) {
        p.command = MemoryAreaWrite::code;
        w.u8(p.command.main);
        w.u8(p.command.sub);
        const auto local = locate_instruction_words(plc_.memory(), request);
        std::array<std::uint8_t, 2 * max_instruction_words> data{};
        ByteWriter dw{MutableBytes{data.data(), data.size()}};
        plc_.memory().read(*local, dw, std::chrono::system_clock::now());
        MemoryAreaWrite{*to_memory_address(request.remote, Access::word), request.count,
                        Bytes{data.data(), dw.size()}}
            .encode(w);
    } else {
        p.command = MemoryAreaRead::code;
        w.u8(p.command.main);
        w.u8(p.command.sub);
        MemoryAreaRead{*to_memory_address(request.remote, Access::word), request.count}.encode(w);
    }
    p.frame_size = w.size();
    p.request = std::move(request);
    p.answered = false;
    transmit(index);
}

void NetworkInstructions::transmit(std::size_t index) {
    Port& p = *ports_[index];
    ++p.transmissions;
    const auto sent =
        transport_.send_frame(p.request.destination, Bytes{p.frame.data(), p.frame_size}, p.route);
    if (sent == InstructionTransport::Sent::no_route)
        return finish(index, communications_error(EndCode::destination_address_setting_error,
                                                  "no IP address for that network/node "
                                                  "(see [[remote]])"));
    if (sent == InstructionTransport::Sent::no_port)
        return finish(index, communications_error(EndCode::local_node_not_in_network,
                                                  "FINS/UDP is off on this node and no FINS/TCP "
                                                  "connection holds that node"));
    if (sent == InstructionTransport::Sent::not_established)
        return finish(index, communications_error(EndCode::local_node_not_in_network,
                                                  "the FINS/TCP connection to that node is not "
                                                  "established"));
    if (sent == InstructionTransport::Sent::failed && p.transmissions > p.request.options.retries)
        return finish(index,
                      communications_error(EndCode::retries_failed, "the frame could not be sent"));
    const bool no_answer = (p.frame[0] & icf_no_response) != 0;
    if (no_answer && sent == InstructionTransport::Sent::ok) {
        p.answered = true;  // nothing answers it: its SID needs no quarantine
        InstructionResult r;
        r.detail = "sent (no response requested)";
        return finish(index, std::move(r));
    }
    arm(index);
}

void NetworkInstructions::arm(std::size_t index) {
    Port& p = *ports_[index];
    const auto generation = ++p.generation;
    p.timer.expires_after(instruction_timeout(p.request.options.timeout));
    p.timer.async_wait([this, index, generation,
                        alive = std::weak_ptr<bool>(alive_)](boost::system::error_code ec) {
        const auto a = alive.lock();
        if (ec || !a || !*a) return;
        on_timeout(index, generation);
    });
}

void NetworkInstructions::on_timeout(std::size_t index, std::uint64_t generation) {
    Port& p = *ports_[index];
    if (!p.busy || p.generation != generation) return;
    transport_.unanswered(p.route);
    if (p.transmissions <= p.request.options.retries) {
        ++counters_.retransmissions;
        return transmit(index);
    }
    ++counters_.timeouts;
    finish(index, communications_error(
                      EndCode::response_timeout,
                      fmt::format("no response after {} transmission(s)", p.transmissions)));
}

bool NetworkInstructions::answers(const Port& p, const Header& h,
                                  const InstructionRoute& from) const noexcept {
    if (!p.route.same_way(from)) return false;
    const auto& dest = p.request.destination;
    // Network 00 is the local network: its nodes answer with 00 or its number.
    const auto local = [&](std::uint8_t network) {
        return network == local_network || network == self_.network;
    };
    const bool network =
        h.source.network == dest.network || (local(dest.network) && local(h.source.network));
    // Node 00 addresses "this PLC": its answer comes from our own node number.
    const std::uint8_t node = dest.node == 0 ? self_.node : dest.node;
    const std::uint8_t me = p.route.local_node != 0 ? p.route.local_node : self_.node;
    return network && h.source.node == node && h.source.unit == dest.unit &&
           (h.destination.node == me || h.destination.node == 0);
}

bool NetworkInstructions::on_response(Bytes frame, const InstructionRoute& from) {
    const auto view = decode_response(frame);
    if (!view) {
        ++counters_.unmatched;
        return false;
    }
    const Header& h = view->header;
    const auto it = std::find_if(ports_.begin(), ports_.end(), [&](const auto& p) {
        return p->busy && p->sid == h.service_id && p->command == view->command &&
               answers(*p, h, from);
    });
    if (it == ports_.end()) {
        ++counters_.unmatched;
        return false;
    }
    const auto index = static_cast<std::size_t>(it - ports_.begin());
    Port& p = **it;
    p.answered = true;
    InstructionResult r;
    r.end_code = view->code.raw();
    if (p.request.kind == InstructionKind::sendcmd)
        r.response.assign(frame.begin() + header_size, frame.end());
    if (!view->code.ok() || view->code.relay_error()) {
        r.error_id = instruction_communications_error;
        r.error_id_ex = view->code.raw();
        const auto* info = find_end_code(view->code.raw() & 0x7F3F);
        r.detail = fmt::format("the remote answered {:04X} ({})", view->code.raw(),
                               info ? info->name : "unknown end code");
        finish(index, std::move(r));
        return true;
    }
    if (p.request.kind == InstructionKind::recv) {
        const auto want = std::size_t{p.request.count} * 2;
        if (view->data.size() != want) {
            r.error_id = instruction_communications_error;
            r.error_id_ex = static_cast<std::uint16_t>(EndCode::elements_data_mismatch);
            r.detail =
                fmt::format("the answer holds {} bytes, {} expected", view->data.size(), want);
            finish(index, std::move(r));
            return true;
        }
        auto local = locate_instruction_words(plc_.memory(), p.request);
        if (!local || plc_.memory().write(*local, view->data) != EndCode::normal_completion) {
            r.error_id = instruction_parameter_error;
            r.detail = "the local words cannot be written";
            finish(index, std::move(r));
            return true;
        }
        r.words.reserve(p.request.count);
        for (std::size_t i = 0; i + 1 < view->data.size(); i += 2)
            r.words.push_back(static_cast<std::uint16_t>((view->data[i] << 8) | view->data[i + 1]));
    }
    const auto kind = p.request.kind;
    r.detail = kind == InstructionKind::send   ? fmt::format("wrote {} words", p.request.count)
               : kind == InstructionKind::recv ? fmt::format("read {} words", p.request.count)
                                               : std::string("answered");
    finish(index, std::move(r));
    return true;
}

void NetworkInstructions::finish(std::size_t index, InstructionResult result) {
    Port& p = *ports_[index];
    ++p.generation;
    p.timer.cancel();
    release_sid(p, p.answered);
    p.busy = false;
    --in_flight_;
    result.port = static_cast<int>(index);
    result.transmissions = p.transmissions;
    ++(result.done() ? counters_.done : counters_.errors);
    // CS/CJ completion code: the end code (0000 normal), or the local error's code.
    const std::uint16_t completion = result.done() ? std::uint16_t{0} : result.error_id_ex;
    metrics::note_instruction(static_cast<std::uint8_t>(p.request.kind), completion);
    show_port(index, false,
              result.error_id == instruction_parameter_error
                  ? std::optional<std::uint16_t>{}
                  : std::optional<std::uint16_t>{completion});
    if (!result.done())
        spdlog::debug("finsd: {} to {}.{}.{} port {}: ErrorID {:04X} {:04X}: {}",
                      instruction_kind_name(p.request.kind), p.request.destination.network,
                      p.request.destination.node, p.request.destination.unit, index,
                      result.error_id, result.error_id_ex, result.detail);
    complete_later(std::move(p.done), std::move(result));
    p.done = nullptr;
}

void NetworkInstructions::show_port(std::size_t port, bool busy,
                                    std::optional<std::uint16_t> completion) {
    if (!flags_ || port >= flagged_ports) return;
    auto a = plc_.memory().words(Region::auxiliary);
    if (a.size() <= a_port_error) return;
    const auto bit = static_cast<std::uint16_t>(1U << port);
    a[a_port_enabled] = busy ? static_cast<std::uint16_t>(a[a_port_enabled] & ~bit)
                             : static_cast<std::uint16_t>(a[a_port_enabled] | bit);
    if (completion) {
        a[a_completion_first + port] = *completion;
        a[a_port_error] = *completion != 0 ? static_cast<std::uint16_t>(a[a_port_error] | bit)
                                           : static_cast<std::uint16_t>(a[a_port_error] & ~bit);
    }
}

}  // namespace fins::server
