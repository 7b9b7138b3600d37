// The Send/Rcv/SendCmd engine without sockets (W596 3): a fake transport records the
// frames, the test answers them; the io_context runs the timers and callbacks. Shared by
// network_instructions_test.cpp and network_instructions_sid_test.cpp.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "server/instructions/network_instructions.hpp"
#include "transport/asio.hpp"

namespace fins::test {

using server::InstructionKind;
using server::InstructionRequest;
using server::InstructionResult;
using server::InstructionTransport;
using server::NetworkInstructions;

struct FakeTransport : InstructionTransport {
    Sent send_frame(const NodeAddress& destination, Bytes frame,
                    server::InstructionRoute& way) override {
        destinations.push_back(destination);
        frames.emplace_back(frame.begin(), frame.end());
        way = route;
        return answer;
    }
    void unanswered(const server::InstructionRoute& way) override {
        unanswered_routes.push_back(way);
    }
    Sent answer = Sent::ok;
    // Where the remote node is (the node address table's entry).
    server::InstructionRoute route{{asio::ip::make_address("127.0.0.5"), 9600}, nullptr, 0};
    std::vector<NodeAddress> destinations;
    std::vector<std::vector<std::uint8_t>> frames;
    std::vector<server::InstructionRoute> unanswered_routes;  // one per timed-out frame
};

inline constexpr NodeAddress self{0, 1, 0};
inline constexpr NodeAddress remote{0, 5, 0};

// The response a remote node sends to `command`: addresses swapped, SID echoed.
inline std::vector<std::uint8_t> answer(const std::vector<std::uint8_t>& command,
                                        std::uint16_t end_code,
                                        std::vector<std::uint8_t> data = {}) {
    std::vector<std::uint8_t> r(command.begin(), command.begin() + 12);
    r[0] = static_cast<std::uint8_t>((command[0] | 0x40) & ~0x01);
    r[3] = command[6];
    r[4] = command[7];
    r[5] = command[8];
    r[6] = command[3];
    r[7] = command[4];
    r[8] = command[5];
    r.push_back(static_cast<std::uint8_t>(end_code >> 8));
    r.push_back(static_cast<std::uint8_t>(end_code));
    r.insert(r.end(), data.begin(), data.end());
    return r;
}

class Engine : public ::testing::Test {
  protected:
    explicit Engine(plc::Profile profile = plc::cj2h())
        : plc_(std::move(profile)), engine_(io_.get_executor(), plc_, self, transport_) {}

    InstructionRequest send(std::uint16_t count) {
        InstructionRequest r;
        r.kind = InstructionKind::send;
        r.destination = remote;
        r.local = *parse_address("D100");
        r.remote = *parse_address("D200");
        r.count = count;
        r.options.timeout = 1;  // 0.1 s
        return r;
    }
    InstructionRequest recv(std::uint16_t count) {
        auto r = send(count);
        r.kind = InstructionKind::recv;
        r.local = *parse_address("D300");
        return r;
    }
    // Starts `r`; `out` receives the result when it completes.
    void start(InstructionRequest r, std::optional<InstructionResult>& out) {
        engine_.start(std::move(r), [&out](const InstructionResult& res) { out = res; });
    }
    // Runs the io_context until `out` is set (bounded).
    void wait(std::optional<InstructionResult>& out) {
        const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (!out && std::chrono::steady_clock::now() < end) {
            io_.restart();
            io_.run_for(std::chrono::milliseconds(20));
        }
        ASSERT_TRUE(out.has_value());
    }
    void poll() {
        io_.restart();
        io_.poll();
    }
    // An answer arriving the way the command went.
    bool respond(const std::vector<std::uint8_t>& frame) {
        return engine_.on_response(Bytes{frame.data(), frame.size()}, transport_.route);
    }
    std::uint16_t a(std::size_t word) { return plc_.memory().words(Region::auxiliary)[word]; }

    asio::io_context io_;
    plc::Plc plc_;
    FakeTransport transport_;
    NetworkInstructions engine_;
};

}  // namespace fins::test
