// fins_gateway_rate: the 28 03 request rate through a Serial Gateway port, against the
// line's own limit. A FINS/UDP client sends CONVERT TO COMPOWAY/F (read variable area,
// one element) to an in-process finsd server whose gateway port is one end of a socat
// pty pair; the simulated controller (fins_compowayf_sim) answers on the other end.
//
//   fins_gateway_rate [--sim PATH] [--seconds N] [--baud B]
//
// A pty moves bytes at memory speed, whatever baud rate is set: the measured rate is
// the gateway's own ceiling (queue, framing, timers, two processes, the pty), not a
// serial line's. The line limit printed beside it is what B baud at 11 bits a character
// (7E2, the Serial Communications Unit default) allows for this exchange.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/client.hpp"
#include "fins/compoway_f.hpp"
#include "integration/support/process.hpp"
#include "integration/support/pty_pair.hpp"
#include "plc/plc.hpp"
#include "server/serial/serial_ports.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

int main(int argc, char** argv) {
    CLI::App app{"28 03 request rate through a Serial Gateway port over a pty"};
    std::string sim = std::string(FINS_BIN_DIR) + "/fins_compowayf_sim";
    double seconds = 3;
    unsigned baud = 115200;
    app.add_option("--sim", sim, "fins_compowayf_sim path");
    app.add_option("--seconds", seconds, "run time");
    app.add_option("--baud", baud, "baud rate for the line limit");
    CLI11_PARSE(app, argc, argv);

    fins::test::PtyPair line;
    if (!line.ok()) {
        std::fprintf(stderr, "socat pty pair failed\n");
        return 1;
    }
    fins::test::Child slave({sim, line.b()});
    if (slave.read_line() != "ready") return 1;

    asio::io_context io{1};
    fins::plc::Plc plc;
    fins::server::ServerOptions options;
    options.port = 0;
    options.tcp = false;
    auto server = fins::server::Server::start(io, plc, options).value();
    fins::server::SerialPorts ports;
    fins::server::GatewayPortConfig config;
    config.name = "scu1.1";
    config.unit_address = fins::server::scu_port_unit_address(1, 1);
    config.line.device = line.a();
    config.line.baud = baud;
    auto port = std::make_shared<fins::server::SerialGatewayPort>(io, config);
    if (port->open()) return 1;
    ports.add(port);
    server->attach_serial_ports(&ports);
    std::thread thread([&] { io.run(); });

    fins::ClientOptions o;
    o.port = server->udp_port();
    o.destination.unit = config.unit_address;
    auto client = fins::Client::connect(o).value();
    const std::string text =
        "01000"
        "0101"
        "C00000000001";
    const std::vector<std::uint8_t> params(text.begin(), text.end());
    std::size_t done = 0;
    std::size_t answer_chars = 0;
    const auto start = std::chrono::steady_clock::now();
    const auto end = start + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
        const auto r = client->send_raw(fins::CommandCode{0x28, 0x03}, params);
        if (!r || r->code.raw() != 0) {
            std::fprintf(stderr, "request failed\n");
            break;
        }
        answer_chars = r->data.size() + 3;  // + STX, ETX, BCC on the line
        ++done;
    }
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    client.reset();
    asio::post(io, [&] {
        ports.close_all();
        server->stop();
        io.stop();
    });
    thread.join();

    const std::size_t request_chars = text.size() + 3;
    const double chars_per_second = baud / 11.0;
    const double line_limit = chars_per_second / static_cast<double>(request_chars + answer_chars);
    const double rate = static_cast<double>(done) / elapsed;
    fmt::print("28 03 through the gateway over a pty: {} requests in {:.2f} s = {:.0f} /s\n", done,
               elapsed, rate);
    fmt::print(
        "line limit at {} baud, 11 bits/char, {} + {} chars per exchange: {:.0f} /s "
        "(measured / limit = {:.1f})\n",
        baud, request_chars, answer_chars, line_limit, rate / line_limit);
    return 0;
}
