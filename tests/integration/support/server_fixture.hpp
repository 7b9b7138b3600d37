// A finsd in the test process: the real Server on its own io_context thread, bound to
// 127.0.0.1 (or ::1) on a free port. Tests talk to it only through sockets, so the
// single-threaded model is never touched from two threads.
#pragma once

#include <memory>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/client.hpp"
#include "plc/plc.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::test {

class ServerThread {
  public:
    // `mode`: the operating mode before the first request (03 07, 03 08 and the file
    // transfers to the program area refuse RUN).
    explicit ServerThread(server::ServerOptions options = {},
                          plc::OperatingMode mode = plc::OperatingMode::run) {
        plc_.set_mode(mode);
        if (options.port == 9600) options.port = 0;
        auto s = server::Server::start(io_, plc_, options);
        if (!s) throw std::runtime_error("server start: " + s.error().message());
        server_ = std::move(*s);
        port_ = server_->tcp_port() != 0 ? server_->tcp_port() : server_->udp_port();
        bind_ = options.bind_address;
        thread_ = std::thread([this] { io_.run(); });
    }
    ~ServerThread() {
        asio::post(io_, [this] {
            server_->stop();
            io_.stop();
        });
        thread_.join();
    }
    [[nodiscard]] std::uint16_t port() const { return port_; }
    [[nodiscard]] const std::string& bind() const { return bind_; }
    // Only while the thread is stopped, or for values fixed at start.
    [[nodiscard]] NodeAddress address() const { return server_->address(); }

    std::unique_ptr<Client> client(bool tcp, ClientOptions o = {}) {
        o.host = bind_;
        o.port = port_;
        o.protocol = tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
        auto c = Client::connect(o);
        EXPECT_TRUE(c.has_value()) << (c ? "" : c.error().message());
        return c ? std::move(*c) : nullptr;
    }

  private:
    asio::io_context io_{1};
    plc::Plc plc_;
    std::unique_ptr<server::Server> server_;
    std::uint16_t port_ = 0;
    std::string bind_;
    std::thread thread_;
};

}  // namespace fins::test
