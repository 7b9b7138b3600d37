// Shared by the RequestTracker tests: a fake wire, a fake clock origin, answers built
// from the request frames, and a fixture with the link up.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/request_tracker.hpp"

namespace fins::test {

using namespace std::chrono_literals;

struct FakeWire : FrameSink {
    std::vector<std::vector<std::uint8_t>> frames;
    void send_frame(Bytes frame) override { frames.emplace_back(frame.begin(), frame.end()); }
};

inline constexpr NodeAddress plc{0, 10, 0};
inline constexpr NodeAddress host{0, 20, 0};
inline constexpr CommandCode read_code{0x01, 0x01};
inline constexpr CommandCode write_code{0x01, 0x02};
inline const SteadyTime t0 = SteadyTime{} + 1h;
// D10, 10 words (W342 5-3-2 example parameters).
inline constexpr std::array<std::uint8_t, 6> read_params{0x82, 0x00, 0x0A, 0x00, 0x00, 0x0A};

inline std::vector<std::uint8_t> answer(Bytes request, std::uint16_t end_code = 0,
                                        std::vector<std::uint8_t> data = {},
                                        NodeAddress responder = plc) {
    auto req = decode_request(request);
    EXPECT_TRUE(req.has_value());
    std::vector<std::uint8_t> out(max_frame_size);
    ByteWriter w(out);
    write_response_prefix(w, response_header(req->header, responder), req->command, end_code);
    w.bytes(data);
    out.resize(w.size());
    return out;
}

// Collects one completion.
struct Outcome {
    std::optional<Result<ResponseView>> result;
    std::vector<std::uint8_t> data;
    RequestTracker::Completion callback() {
        return [this](Result<ResponseView> r) {
            if (r) data.assign(r->data.begin(), r->data.end());
            result = r;
        };
    }
};

class TrackerTest : public ::testing::Test {
  protected:
    TrackerTest() { tracker.link_up(plc, host, t0); }

    // The SID of the frame sent for it (the last frame on the wire).
    std::uint8_t submit(Outcome& o, RequestTiming timing = {}, SteadyTime at = t0,
                        CommandCode code = read_code) {
        auto ok = tracker.submit(code, read_params, timing, o.callback(), at);
        EXPECT_TRUE(ok.has_value());
        return wire.frames.empty() ? 0 : wire.frames.back()[9];
    }

    FakeWire wire;
    RequestTracker tracker{wire};
};

}  // namespace fins::test
