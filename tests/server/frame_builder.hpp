// Test helpers: build FINS request frames from header fields + hex text, run them
// through a Dispatcher over a fresh virtual PLC, and pick the reply apart.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "server/dispatch/dispatcher.hpp"

namespace fins::test {

// "01 01 82000A 00 0A" -> bytes. Spaces ignored; any other non-hex character throws.
std::vector<std::uint8_t> hex(std::string_view text);
// Bytes -> "01 01 82 00" (upper case, one space between bytes).
std::string to_hex(Bytes bytes);

// The node the test dispatcher serves, and the node the test requests come from.
inline constexpr NodeAddress server_node{0x01, 0x0A, 0x00};
inline constexpr NodeAddress client_node{0x01, 0x14, 0x00};

struct FrameFields {
    std::uint8_t icf = 0x80;
    std::uint8_t reserved = 0x00;
    std::uint8_t gateway_count = 0x02;
    NodeAddress destination = server_node;
    NodeAddress source = client_node;
    std::uint8_t service_id = 0x5A;
};

// Header + the command code and parameters given as hex ("0101 82000A00 000A").
std::vector<std::uint8_t> request_frame(std::string_view command_hex, const FrameFields& f = {});

struct Reply {
    std::vector<std::uint8_t> frame;  // empty when the dispatcher returned 0

    [[nodiscard]] bool empty() const noexcept { return frame.empty(); }
    [[nodiscard]] Header header() const;
    [[nodiscard]] CommandCode command() const;
    [[nodiscard]] std::uint16_t end_code() const;  // 0xFFFF when too short to carry one
    [[nodiscard]] std::vector<std::uint8_t> data() const;
    [[nodiscard]] std::string data_hex() const { return to_hex(data()); }
};

// A virtual PLC (default profile unless given) behind a Dispatcher at server_node.
class Harness {
  public:
    explicit Harness(plc::Profile profile = plc::cj2h());

    Reply send(Bytes frame);
    Reply send(std::string_view command_hex, const FrameFields& f = {});

    plc::Plc plc;
    plc::IoMemory& memory() { return plc.memory(); }
    server::Dispatcher dispatcher;
    server::RequestContext context{};

  private:
    std::array<std::uint8_t, max_frame_size> out_{};
};

}  // namespace fins::test
