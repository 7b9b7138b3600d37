#include "bridge/poll/tag_decode.hpp"

#include <cmath>

#include "fins/commands/memory_area.hpp"
#include "fins/values.hpp"

namespace fins::bridge {

namespace {

std::uint16_t word_at(Bytes data, std::size_t index) {
    return static_cast<std::uint16_t>((data[2 * index] << 8) | data[2 * index + 1]);
}

}  // namespace

void decode_words(const Tag& tag, Bytes data, std::size_t offset, TagSample& s) {
    s.error = {};
    if (tag.type == TagType::bits) {
        s.value.words[0] =
            static_cast<std::uint16_t>((word_at(data, offset) >> tag.address.bit.value_or(0)) & 1);
        return;
    }
    if (tag.type == TagType::string) {
        std::uint16_t words[max_read_words];
        for (std::size_t i = 0; i < tag.words; ++i)
            words[i] = word_at(data, offset + i);
        // An odd length leaves the last word's low byte outside the tag. Cut it from the
        // word, not from the text: a character above U+007F is two bytes of UTF-8.
        if (tag.length % 2 != 0 && tag.words > 0) words[tag.words - 1] &= 0xFF00;
        s.value.text = words_to_string({words, tag.words});
        return;
    }
    // Words past the tag's own stay 0 from the first decode: TagValue compares all four.
    for (std::size_t i = 0; i < tag.words; ++i)
        s.value.words[i] = word_at(data, offset + i);
}

void decode_items(const Tag& tag, Bytes data, const std::uint16_t* item_offsets, std::size_t first,
                  TagSample& s) {
    s.error = {};
    if (tag.flag) {
        s.value.words[0] = data[item_offsets[first]] & 1;
        return;
    }
    for (std::size_t k = 0; k < tag.words; ++k) {
        const auto at = item_offsets[first + k];
        s.value.words[k] = static_cast<std::uint16_t>((data[at] << 8) | data[at + 1u]);
    }
    if (tag.type == TagType::bits)
        s.value.words[0] = (s.value.words[0] >> tag.address.bit.value_or(0)) & 1;
}

bool changed(const Tag& tag, double group_deadband, const TagSample& now, const TagSample& before) {
    if (now.error || before.error) return now.error != before.error;
    if (tag.type == TagType::string) return now.value.text != before.value.text;
    const double band = tag.deadband.value_or(group_deadband);
    if (band > 0)
        return std::abs(numeric(tag.type, now.value) - numeric(tag.type, before.value)) > band;
    return now.value.words != before.value.words;
}

}  // namespace fins::bridge
