// Answers into tag values, and values into "changed?": the part of polling that knows
// the data layout of 01 01 and 01 04 answers and the publish rules. Pure (no sockets, no
// clock).
#pragma once

#include <cstddef>
#include <cstdint>

#include "bridge/config.hpp"
#include "bridge/payload.hpp"
#include "fins/byte_io.hpp"

namespace fins::bridge {

// The tag's value from an 01 01 answer whose words start `offset` words before it.
void decode_words(const Tag& tag, Bytes data, std::size_t offset, TagSample& s);

// The tag's value from an 01 04 answer: `item_offsets[k]` is the byte offset of element
// k's value in `data`; the tag's elements start at `first`.
void decode_items(const Tag& tag, Bytes data, const std::uint16_t* item_offsets, std::size_t first,
                  TagSample& s);

// Whether `now` is to be published against the last published `before` (which exists):
// errors and strings compare equal or not, numbers by the deadband (tag's, else
// `group_deadband`), with no deadband by their words.
bool changed(const Tag& tag, double group_deadband, const TagSample& now, const TagSample& before);

}  // namespace fins::bridge
