// PlcPoller's private state shared by its source files (poller.cpp: scheduling, the
// client and its answers; poller_write.cpp: writes; poller_offline.cpp: online,
// offline and back-off). Not for use outside the poller.
#pragma once

#include <cstdint>
#include <string>
#include <system_error>
#include <vector>

#include "bridge/poll/poller.hpp"

namespace fins::bridge {

struct PlcPoller::GroupState {
    GroupState(asio::io_context& io, const Group& g) : cfg(g), timer(io) {}
    const Group& cfg;
    Plan plan;
    std::vector<std::vector<std::uint8_t>> parameters;     // encoded once per frame
    std::vector<CommandCode> commands;                     // 01 01 or 01 04, per frame
    std::vector<std::vector<std::uint16_t>> item_offsets;  // 01 04: byte offset of each value
    std::vector<std::size_t> answer_sizes;                 // expected response data bytes
    // Per tag: its words when its value is the words as read (not bits, flag or string),
    // else 0 (decode_words() then).
    std::vector<std::uint8_t> plain_words;
    std::vector<TagSample> samples;
    std::vector<TagSample> published;
    std::vector<bool> have_published;
    asio::steady_timer timer;
    TickGrid grid;
    std::size_t outstanding = 0;
    bool in_cycle = false;
    bool need_full = true;
    PollClock::time_point last_full;
};

struct PendingWrite {
    std::string id;
    const Tag* tag = nullptr;
    std::vector<std::uint8_t> parameters;
    std::uint16_t end_code = 0;
    bool waiting = false;  // behind an earlier write of the same words (poller_write.cpp)
};

inline bool is_end_code(std::error_code ec) {
    return ec.category() == end_code_category();
}

}  // namespace fins::bridge
