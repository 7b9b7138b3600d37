// What the UDP and the FINS/TCP transports share (udp_transport.cpp, tcp_transport.cpp): the
// open prologue (close what was open, keep the open handler, bound the whole open by
// TransportOptions::open_timeout, resolve host:port), the part of close() that ends a
// connection, and the state the two keep alike.
//
// Handlers capture `life_` (a weak_ptr, expired once the transport is destroyed) and the
// `generation_` they were started in (bumped by every close): a handler of a destroyed
// transport or of an older connection returns without touching anything.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>

#include "fins/error.hpp"
#include "transport/asio.hpp"
#include "transport/transport.hpp"
#include "transport/write_queue.hpp"

namespace fins::transport {

// Protocol: asio::ip::udp or asio::ip::tcp.
template <class Protocol>
class SocketTransport : public Transport {
  public:
    [[nodiscard]] State state() const noexcept final { return state_; }
    [[nodiscard]] bool write_pending() const noexcept final { return !queue_.empty(); }

  protected:
    using Resolved = typename Protocol::resolver::results_type;

    SocketTransport(asio::io_context& io, TransportOptions options)
        : options_(std::move(options)), resolver_(io), socket_(io), open_timer_(io) {}

    // The open prologue: closes, keeps `done` for finish_open(), arms the open timeout
    // (finish_open(ClientError::timeout)) and resolves host:port. A resolver error goes to
    // finish_open(); the addresses to `on_resolved(const Resolved&)`, which connects.
    template <class OnResolved>
    void begin_open(OpenHandler done, OnResolved on_resolved) {
        close();
        state_ = State::opening;
        open_done_ = std::move(done);
        auto gen = generation_;
        std::weak_ptr<int> life = life_;
        open_timer_.expires_after(options_.open_timeout);
        open_timer_.async_wait([this, life, gen](boost::system::error_code ec) {
            if (life.expired() || gen != generation_ || ec || state_ != State::opening) return;
            finish_open(Unexpected(make_error_code(ClientError::timeout)));
        });
        // An address is not looked up: Asio resolves on one thread for the whole io_context,
        // and a lookup that waits for a silent DNS server (a broker's name in fins-bridge,
        // another PLC's) would hold this PLC up behind it. (A scoped IPv6 address, "::1%eth0",
        // goes to getaddrinfo, which refuses an interface that does not exist; Asio's parser
        // would take it as scope 0.)
        boost::system::error_code not_an_address;
        const auto address = asio::ip::make_address(options_.host, not_an_address);
        if (!not_an_address && options_.host.find('%') == std::string::npos) {
            asio::post(socket_.get_executor(),
                       [this, life, gen, on_resolved = std::move(on_resolved),
                        results = Resolved::create({address, options_.port}, options_.host,
                                                   std::to_string(options_.port))] {
                           if (life.expired() || gen != generation_) return;
                           on_resolved(results);
                       });
            return;
        }
        resolver_.async_resolve(options_.host, std::to_string(options_.port),
                                Protocol::resolver::numeric_service,
                                [this, life, gen, on_resolved = std::move(on_resolved)](
                                    boost::system::error_code ec, const Resolved& results) {
                                    if (life.expired() || gen != generation_) return;
                                    if (ec) return finish_open(Unexpected(ec));
                                    on_resolved(results);
                                });
    }

    // Ends the open with `result` (the transport's own steps: state, reading, the handler).
    virtual void finish_open(Result<LinkInfo> result) = 0;

    // The open handler, taken once: the open is decided, its timer stops.
    OpenHandler take_open_handler() {
        open_timer_.cancel();
        auto done = std::move(open_done_);
        open_done_ = nullptr;
        return done;
    }

    // The part of close() both share: handlers of this connection are disowned, the
    // resolver, timer and socket stop, queued frames are dropped.
    void close_connection() {
        ++generation_;
        boost::system::error_code ignored;
        resolver_.cancel();
        open_timer_.cancel();
        socket_.close(ignored);
        queue_.clear();
        writing_ = false;
        open_done_ = nullptr;
        state_ = State::closed;
    }

    // An open transport failed: closes it, then tells the close handler why.
    void fail(boost::system::error_code reason) {
        close();
        if (on_close_) on_close_(reason);
    }

    TransportOptions options_;
    typename Protocol::resolver resolver_;
    typename Protocol::socket socket_;
    asio::steady_timer open_timer_;
    State state_ = State::closed;
    std::uint64_t generation_ = 0;  // bumped on close: handlers of older sockets ignore
    std::shared_ptr<int> life_ = std::make_shared<int>(0);  // handlers check it is alive
    OpenHandler open_done_;
    WriteQueue queue_;
    bool writing_ = false;
};

}  // namespace fins::transport
