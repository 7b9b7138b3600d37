// NetworkInstructions: Send, Rcv and SendCmd (network_instructions.hpp, W596 3).
#include "server/instructions/network_instructions.hpp"

#include <algorithm>
#include <iterator>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

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

InstructionResult refused(InstructionTransport::Sent why) {
    using Sent = InstructionTransport::Sent;
    switch (why) {
        case Sent::no_route:
            return communications_error(EndCode::destination_address_setting_error,
                                        "no IP address for that network/node (see [[remote]])");
        case Sent::no_port:
            return communications_error(EndCode::local_node_not_in_network,
                                        "FINS/UDP is off on this node and no FINS/TCP "
                                        "connection holds that node");
        case Sent::not_established:
            return communications_error(EndCode::local_node_not_in_network,
                                        "the FINS/TCP connection to that node is not "
                                        "established");
        case Sent::ok:
        case Sent::failed:
            break;
    }
    return communications_error(EndCode::retries_failed, "the frame could not be sent");
}

}  // namespace

// One instruction port: its request and the way its last frame went (allocated on first
// use, then kept). The frame, SID, timer and retries are the tracker's.
struct NetworkInstructions::Port {
    bool busy = false;
    InstructionRequest request;
    InstructionCallback done;
    InstructionRoute route;  // the way the last transmission went
    InstructionTransport::Sent sent = InstructionTransport::Sent::ok;  // the last send's
    unsigned transmissions = 0;
};

// The node's request engine: the RequestTracker with the instruction transport as its
// sink (tag = port), the route check as its answer check, and the one timer that covers
// its next deadline.
struct NetworkInstructions::Link final : FrameSink, AnswerCheck {
    explicit Link(NetworkInstructions& o) : owner(o), timer(o.executor_) {
        // As before the one engine: 32 instructions at most, so a clean SID comes round
        // again after 224 others; no round-trip rest on top (it stalled 32 in flight).
        tracker.set_rest_clean_ids(false);
        // Every request names its own destination and source (RequestOptions): the link's
        // addresses are never used.
        tracker.link_up(o.self_, o.self_, now());
    }
    Link(const Link&) = delete;
    Link& operator=(const Link&) = delete;
    ~Link() = default;

    static SteadyTime now() noexcept { return std::chrono::steady_clock::now(); }

    // A frame of no port's (the tracker sends requests' frames by send_request()): it
    // goes where its header says.
    void send_frame(Bytes frame) override {
        ByteReader r{frame};
        InstructionRoute route;
        (void)owner.transport_.send_frame(read_header(r).destination, frame, route);
    }
    std::error_code send_request(Bytes frame, std::uintptr_t tag, bool last) override {
        using Sent = InstructionTransport::Sent;
        Port& p = *owner.ports_[tag];
        ++p.transmissions;
        p.sent = owner.transport_.send_frame(p.request.destination, frame, p.route);
        // The kernel refused a frame a retry follows: as if it were lost on the way, the
        // instruction's timeout sends it again (W596 3 Option.Retry).
        if (p.sent == Sent::ok || (p.sent == Sent::failed && !last)) return {};
        return make_error_code(ClientError::not_connected);  // on_answer() reads p.sent
    }
    void unanswered(std::uintptr_t tag) override {
        owner.transport_.unanswered(owner.ports_[tag]->route);
    }

    // True when `h`, arrived by `from`, is the answer port `tag`'s command asked for (the
    // tracker has checked its SID and command code).
    bool answers(std::uintptr_t tag, const Header& request, const Header& h) override {
        (void)request;
        const Port& p = *owner.ports_[tag];
        if (from == nullptr || !p.route.same_way(*from)) return false;
        const auto& self = owner.self_;
        const auto& dest = p.request.destination;
        // Network 00 is the local network: its nodes answer with 00 or its number.
        const auto local = [&](std::uint8_t network) {
            return network == local_network || network == self.network;
        };
        const bool network =
            h.source.network == dest.network || (local(dest.network) && local(h.source.network));
        // Node 00 addresses "this PLC": its answer comes from our own node number.
        const std::uint8_t node = dest.node == 0 ? self.node : dest.node;
        // A FINS/TCP client connection names this node by the node its handshake gave.
        const std::uint8_t me = p.route.local_node != 0 ? p.route.local_node : self.node;
        return network && h.source.node == node && h.source.unit == dest.unit &&
               (h.destination.node == me || h.destination.node == 0);
    }

    // Makes sure the timer fires no later than the tracker's next deadline (fins::Client's
    // rule: a timer armed earlier than needed is left alone).
    void rearm() {
        const auto next = tracker.next_deadline();
        if (!next || (armed && *armed <= *next)) return;
        armed = next;
        const auto generation = ++timer_generation;
        timer.expires_at(*next);
        timer.async_wait([this, generation,
                          alive = std::weak_ptr<bool>(owner.alive_)](boost::system::error_code ec) {
            const auto a = alive.lock();
            if (ec || !a || !*a || generation != timer_generation) return;
            armed.reset();
            tracker.on_timer(now());
            owner.counters_.retransmissions = tracker.stats().retransmitted;
            rearm();
        });
    }
    void disarm() {
        ++timer_generation;
        armed.reset();
        timer.cancel();
    }

    NetworkInstructions& owner;
    RequestTracker tracker{*this, default_gateway_count, max_instructions};
    asio::steady_timer timer;
    std::optional<SteadyTime> armed;
    std::uint64_t timer_generation = 0;
    // The answer being matched (on_response()): the way it came and its bytes.
    const InstructionRoute* from = nullptr;
    Bytes answer_frame;
};

NetworkInstructions::NetworkInstructions(asio::any_io_executor executor, plc::Plc& plc,
                                         NodeAddress self, InstructionTransport& transport)
    : executor_(std::move(executor)), plc_(plc), self_(self), transport_(transport) {
    // Ports are made on first use (start()): a plant of 1,000 CPU Units that never sends
    // would otherwise keep 32 ports resident in each.
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
        p->busy = false;  // on_answer() ignores what cancel_all() reports below
        p->done = nullptr;
    }
    in_flight_ = 0;
    if (!link_) return;
    link_->disarm();
    // Unanswered SIDs are quarantined as usual: a late answer still finds none of them.
    link_->tracker.cancel_all(make_error_code(ClientError::canceled), Link::now());
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
        ports_.push_back(std::make_unique<Port>());
        free = std::prev(ports_.end());
    }
    if (free == ports_.end()) {
        ++counters_.errors;
        return complete_later(std::move(done),
                              communications_error(EndCode::too_many_send_frames,
                                                   "32 instructions are already running"));
    }
    if (!link_) link_ = std::make_unique<Link>(*this);
    const auto index = static_cast<std::size_t>(free - ports_.begin());

    // The command's parameters, once: the tracker builds the frame, and a retry sends the
    // same frame with the same SID.
    CommandCode command;
    std::array<std::uint8_t, max_frame_size> parameters{};
    ByteWriter w{MutableBytes{parameters.data(), parameters.size()}};
    if (request.kind == InstructionKind::sendcmd) {
        command = CommandCode{request.command[0], request.command[1]};
        w.bytes(Bytes{request.command.data() + command_code_size,
                      request.command.size() - command_code_size});
    } else if (request.kind == InstructionKind::send) {
        command = MemoryAreaWrite::code;
        const auto local = locate_instruction_words(plc_.memory(), request);
        std::array<std::uint8_t, 2 * max_instruction_words> data{};
        ByteWriter dw{MutableBytes{data.data(), data.size()}};
        plc_.memory().read(*local, dw, std::chrono::system_clock::now());
        MemoryAreaWrite{*to_memory_address(request.remote, Access::word), request.count,
                        Bytes{data.data(), dw.size()}}
            .encode(w);
    } else {
        command = MemoryAreaRead::code;
        MemoryAreaRead{*to_memory_address(request.remote, Access::word), request.count}.encode(w);
    }

    Port& p = **free;
    p.busy = true;
    p.done = std::move(done);
    p.transmissions = 0;
    p.sent = InstructionTransport::Sent::ok;
    p.request = std::move(request);
    ++in_flight_;
    show_port(index, true, std::nullopt);

    const auto timeout = instruction_timeout(p.request.options.timeout);
    RequestOptions options;
    options.destination = p.request.destination;
    options.source = NodeAddress{self_.network, self_.node, cpu_unit};
    options.tag = index;
    // Twice the instruction's own timeout (fins::Client: default_quarantine_timeouts).
    options.quarantine = timeout * default_quarantine_timeouts;
    const Bytes text{parameters.data(), w.size()};
    if (p.request.options.no_response || p.request.destination.node == broadcast_node) {
        if (!link_->tracker.submit_no_response(command, text, options))
            return finish(index, refused(p.sent));
        InstructionResult r;
        r.detail = "sent (no response requested)";
        return finish(index, std::move(r));
    }
    auto submitted = link_->tracker.submit(
        command, text, RequestTiming{timeout, p.request.options.retries},
        [this, index](Result<ResponseView> answer) { on_answer(index, std::move(answer)); },
        Link::now(), options);
    if (!submitted)  // not expected: 32 ports, 256 request slots, frames checked above
        return finish(index, communications_error(EndCode::too_many_send_frames,
                                                  submitted.error().message()));
    link_->rearm();
}

void NetworkInstructions::on_answer(std::size_t index, Result<ResponseView> answer) {
    Port& p = *ports_[index];
    if (!p.busy) return;  // stop()
    if (answer) return finish(index, result_of(index, *answer));
    if (answer.error() == make_error_code(ClientError::timeout)) {
        ++counters_.timeouts;
        return finish(index, communications_error(EndCode::response_timeout,
                                                  fmt::format("no response after {} "
                                                              "transmission(s)",
                                                              p.transmissions)));
    }
    finish(index, refused(p.sent));
}

bool NetworkInstructions::on_response(Bytes frame, const InstructionRoute& from) {
    if (!link_) {
        ++counters_.unmatched;
        return false;
    }
    link_->from = &from;
    link_->answer_frame = frame;
    const auto disposition = link_->tracker.on_frame(frame, Link::now(), link_.get());
    link_->from = nullptr;
    link_->answer_frame = {};
    if (disposition != RequestTracker::Disposition::matched) {
        ++counters_.unmatched;
        return false;
    }
    link_->rearm();  // a request that waited for a SID may have been sent
    return true;
}

InstructionResult NetworkInstructions::result_of(std::size_t index, const ResponseView& view) {
    const Port& p = *ports_[index];
    const Bytes frame = link_->answer_frame;
    InstructionResult r;
    r.end_code = view.code.raw();
    if (p.request.kind == InstructionKind::sendcmd)
        r.response.assign(frame.begin() + header_size, frame.end());
    if (!view.code.ok() || view.code.relay_error()) {
        r.error_id = instruction_communications_error;
        r.error_id_ex = view.code.raw();
        const auto* info = find_end_code(view.code.raw() & 0x7F3F);
        r.detail = fmt::format("the remote answered {:04X} ({})", view.code.raw(),
                               info ? info->name : "unknown end code");
        return r;
    }
    if (p.request.kind == InstructionKind::recv) {
        const auto want = std::size_t{p.request.count} * 2;
        if (view.data.size() != want) {
            r.error_id = instruction_communications_error;
            r.error_id_ex = static_cast<std::uint16_t>(EndCode::elements_data_mismatch);
            r.detail =
                fmt::format("the answer holds {} bytes, {} expected", view.data.size(), want);
            return r;
        }
        auto local = locate_instruction_words(plc_.memory(), p.request);
        if (!local || plc_.memory().write(*local, view.data) != EndCode::normal_completion) {
            r.error_id = instruction_parameter_error;
            r.detail = "the local words cannot be written";
            return r;
        }
        r.words.reserve(p.request.count);
        for (std::size_t i = 0; i + 1 < view.data.size(); i += 2)
            r.words.push_back(static_cast<std::uint16_t>((view.data[i] << 8) | view.data[i + 1]));
    }
    const auto kind = p.request.kind;
    r.detail = kind == InstructionKind::send   ? fmt::format("wrote {} words", p.request.count)
               : kind == InstructionKind::recv ? fmt::format("read {} words", p.request.count)
                                               : std::string("answered");
    return r;
}

void NetworkInstructions::finish(std::size_t index, InstructionResult result) {
    Port& p = *ports_[index];
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
