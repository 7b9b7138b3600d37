// The request planner (pure: tags in, frames out; no I/O, no clock).
//
// A group's tags are merged into as few frames as possible:
// - 01 01 MEMORY AREA READ for runs of one area code whose tags lie within `gap_words`
//   of each other, up to 999 words a frame (W342 5-3-2; 999 x 2 bytes of data plus the
//   14-byte response header is exactly the 2,012-byte frame limit, W342 5-2-2);
// - 01 04 MULTIPLE MEMORY AREA READ for scattered points: a tag alone in its run (and
//   every T/C/TK flag) becomes 1-2 elements, up to 167 elements a frame (W342 5-3-5).
//   A 01 04 frame that would carry a single tag is sent as 01 01 instead.
// Every tag is read by exactly one frame; TagSlot says where its words are in the answer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bridge/config.hpp"
#include "fins/memory_area.hpp"

namespace fins::bridge {

struct PlannedFrame {
    enum class Kind : std::uint8_t { read, multiple_read };
    Kind kind = Kind::read;
    MemoryAddress start;               // read: first word
    std::uint16_t count = 0;           // read: words
    std::vector<MemoryAddress> items;  // multiple_read: one per element
    std::vector<std::size_t> tags;     // indices of the tags it carries
};

struct TagSlot {
    std::uint16_t frame = 0;
    // read: the tag's first word relative to the frame's start;
    // multiple_read: the index of the tag's first element.
    std::uint16_t offset = 0;
};

struct Plan {
    std::vector<PlannedFrame> frames;
    std::vector<TagSlot> slots;  // one per tag, in the group's order
};

Plan plan_group(std::span<const Tag> tags, std::size_t gap_words);

// One line per frame, as `fins-bridge --plan` prints it:
//   01 01 D100 x 12 words: speed temp
//   01 04 3 elements: run T5 D900
std::string describe_plan(const Plan& plan, std::span<const Tag> tags);

}  // namespace fins::bridge
