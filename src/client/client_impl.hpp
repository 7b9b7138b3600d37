// fins::Client's state: the io_context, the transport, the request tracker and the one
// timer that covers the tracker's next deadline. Private to src/client.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "engine/request_tracker.hpp"
#include "fins/client.hpp"
#include "fins/host_link.hpp"
#include "transport/asio.hpp"
#include "transport/host_link_transport.hpp"
#include "transport/tcp_transport.hpp"
#include "transport/udp_transport.hpp"

namespace fins {

inline SteadyTime now() {
    return std::chrono::steady_clock::now();
}

// UDP to 127.0.0.1 derives node 1 for both ends; a source equal to the destination would
// look like the PLC talking to itself (W421 7-4 refuses it on TCP with error 0x24).
inline constexpr std::uint8_t fallback_source_node = 254;

struct Client::Impl final : FrameSink {
    // `external`: the caller's io_context (Client::create); null: an own one (connect).
    Impl(ClientOptions o, asio::io_context* external)
        : own_io(external ? nullptr : std::make_unique<asio::io_context>(1)),
          io(external ? *external : *own_io),
          embedded(external != nullptr),
          options(std::move(o)),
          tracker(*this, options.gateway_count),
          timer(io) {
        tracker.set_quarantine(quarantine());
        tracker.set_exact_destination(options.destination_as_given);
        transport::TransportOptions t;
        t.host = options.host;
        t.port = options.port;
        t.open_timeout = options.timeout;
        t.requested_node = options.source.node;
        if (options.protocol == ClientOptions::Protocol::serial) {
            transport = std::make_unique<transport::HostLinkTransport>(
                io, transport::HostLinkOptions{options.serial, options.host_link_unit, 0});
            tracker.set_window(1);  // half duplex
            tracker.set_max_frame(host_link_max_fins_command);
        } else if (options.protocol == ClientOptions::Protocol::tcp)
            transport = std::make_unique<transport::TcpTransport>(io, std::move(t));
        else
            transport = std::make_unique<transport::UdpTransport>(io, std::move(t));
        // A frame only ends or sends requests whose deadlines are covered already; while
        // requests wait for a SID, the SID it freed may be usable before the armed time.
        transport->set_frame_handler([this](Bytes frame) {
            tracker.on_frame(frame, now());
            if (tracker.waiting() > 0) rearm();
        });
        transport->set_close_handler([this](std::error_code reason) {
            tracker.link_down(reason);
            rearm();
        });
        // The transport stays open (e.g. UDP port unreachable): fail what waits.
        // Host Link: an error answer ends only the request on the line.
        transport->set_error_handler([this](std::error_code reason) {
            if (options.protocol == ClientOptions::Protocol::serial)
                tracker.fail_sent(reason, now());
            else
                tracker.cancel_all(reason, now());
            rearm();
        });
    }

    [[nodiscard]] std::chrono::nanoseconds quarantine() const {
        if (options.sid_quarantine.count() > 0) return options.sid_quarantine;
        return options.timeout * default_quarantine_timeouts;
    }

    // Before a request is sent on a link with nothing in flight (its end-of-stream or
    // error may have been waiting unread since the last request, e.g. finsd restarted):
    // notices a dead link now, so the request goes out on a fresh connection.
    // An embedded client's loop keeps running between requests: once the transport has
    // read its socket to the end since the last send, an error would already have been
    // read, and the system call is saved (UDP: once per request on an idle link, which is
    // every poll cycle of the bridge). An own loop stops between calls: always looked at.
    void check_idle_link() {
        if (tracker.in_flight() != 0 || !tracker.is_link_up()) return;
        if (embedded && transport->read_to_end_since_send()) return;
        if (!transport->peer_gone()) return;
        transport->close();
        tracker.link_down(make_error_code(ClientError::connection_closed));  // nothing to fail
    }

    void send_frame(Bytes frame) override { transport->send(frame); }

    // Starts opening unless already open or opening; `notify` hears how the open under
    // way (this one or one started earlier) ends.
    void ensure_open(std::function<void(std::error_code)> notify = nullptr) {
        if (notify) open_waiters.push_back(std::move(notify));
        if (transport->state() != transport::Transport::State::closed) return;
        transport->async_open([this](Result<transport::LinkInfo> r) {
            if (!r) {
                last_open_error = r.error();
                tracker.link_down(r.error());
            } else {
                last_open_error.clear();
                ++opens;
                tracker.link_up(derive_destination(*r), derive_source(*r), now());
            }
            rearm();
            auto waiters = std::move(open_waiters);
            open_waiters.clear();
            for (auto& w : waiters)
                w(r ? std::error_code{} : r.error());
        });
    }

    NodeAddress derive_destination(const transport::LinkInfo& info) const {
        NodeAddress d = options.destination;
        if (d.node == 0 && !options.destination_as_given) d.node = info.remote_node;
        return d;
    }

    NodeAddress derive_source(const transport::LinkInfo& info) const {
        NodeAddress s = options.source;
        if (options.protocol == ClientOptions::Protocol::serial) return s;  // as given
        if (options.protocol == ClientOptions::Protocol::tcp) {
            // The server's answer is authoritative (it may have allocated the node).
            s.node = info.local_node;
            return s;
        }
        if (s.node == 0) {
            s.node = info.local_node;
            auto d = derive_destination(info);
            if (s.node == d.node)
                s.node = d.node == fallback_source_node ? fallback_source_node - 1
                                                        : fallback_source_node;
        }
        return s;
    }

    // Makes sure the timer fires no later than the tracker's next deadline. A timer armed
    // earlier than needed is left alone (it fires, finds nothing due and re-arms), so the
    // common case, a new request whose deadline is later than the armed one, costs
    // nothing.
    void rearm() { arm_by(tracker.next_deadline()); }
    void arm_by(std::optional<SteadyTime> next) {
        if (!next || (armed && *armed <= *next)) return;
        armed = next;
        auto gen = ++timer_generation;
        timer.expires_at(*next);
        timer.async_wait([this, gen](std::error_code ec) {
            if (ec || gen != timer_generation) return;
            armed.reset();
            tracker.on_timer(now());
            arm_by(tracker.next_deadline());
        });
    }

    [[nodiscard]] RequestTiming timing() const { return {options.timeout, options.retries}; }

    // Declaration order is destruction order in reverse: an own io_context goes last, so
    // no handler that refers to the members below can run after they are gone. On the
    // caller's io_context, handlers outlive the Impl: the transport's and the timer's
    // check a generation or an error, posted ones `life`.
    std::unique_ptr<asio::io_context> own_io;
    asio::io_context& io;
    bool embedded = false;
    std::shared_ptr<int> life = std::make_shared<int>(0);
    std::vector<std::function<void(std::error_code)>> open_waiters;
    ClientOptions options;
    std::unique_ptr<transport::Transport> transport;
    RequestTracker tracker;
    asio::steady_timer timer;
    std::optional<SteadyTime> armed;
    std::uint64_t timer_generation = 0;
    std::uint64_t opens = 0;
    std::size_t posted = 0;  // failures posted by fail_later() and not yet delivered
    std::error_code last_open_error;
    int running = 0;  // > 0 while run_until() runs the io_context (handlers run inside)
};

}  // namespace fins
