// A fins-bridge tag of a group: its name, address and type, the frame it is read with,
// checked against the memory-area table and the PLC model (config_loader.hpp).
#include <fmt/format.h>

#include "bridge/config_loader.hpp"

namespace fins::bridge::detail {

Tag Loader::tag(const toml::table& t) {
    only(t, "a tag", {"name", "address", "type", "writable", "deadband", "min", "max", "length"});
    Tag tag;
    tag.name = name(t, "a tag");
    tag.address_text = required_text(t, "address", fmt::format("tag '{}'", tag.name));
    const auto& at = *t.get("address");
    auto a = parse_address(tag.address_text);
    if (!a) fail(at, fmt::format("address '{}': {}", tag.address_text, a.error().message()));
    tag.address = *a;
    const auto type_text = required_text(t, "type", fmt::format("tag '{}'", tag.name));
    auto type = parse_tag_type(type_text);
    if (!type)
        fail(*t.get("type"), fmt::format("type '{}' is not {}", type_text, tag_type_names()));
    tag.type = *type;
    if (auto len = integer(t, "length", 1, 65535)) {
        if (tag.type != TagType::string) fail(*t.get("length"), "length is for string tags");
        tag.length = static_cast<std::size_t>(*len);
    } else if (tag.type == TagType::string) {
        fail(t.source(), fmt::format("string tag '{}' needs length (characters)", tag.name));
    }
    tag.writable = boolean(t, "writable").value_or(false);
    if (auto d = number(t, "deadband")) {
        if (*d < 0) fail(*t.get("deadband"), "deadband must not be negative");
        tag.deadband = *d;
    }
    tag.range.min = number(t, "min");
    tag.range.max = number(t, "max");
    if (tag.range.min && tag.range.max && *tag.range.min > *tag.range.max)
        fail(*t.get("min"), fmt::format("min {} is above max {}: no value could be written",
                                        *tag.range.min, *tag.range.max));
    resolve(at, tag);
    return tag;
}

// Chooses how the tag is read and checks it against the table and the model.
void Loader::resolve(const toml::node& at, Tag& tag) const {
    const Address& a = tag.address;
    const bool is_bool = tag.type == TagType::bits;
    if (a.bit && !is_bool)
        fail(at, fmt::format("'{}' names a bit: its type must be bool", tag.address_text));
    tag.words = tag_words(tag.type, tag.length);
    Address word = a;
    word.bit.reset();
    auto w = to_memory_address(word, Access::word);
    const bool flag_area =
        a.area == Area::timer || a.area == Area::counter || a.area == Area::task_flag;
    if (is_bool && !a.bit) {
        // T5, C3, TK2: the completion / task flag, a 1-byte element.
        if (!flag_area)
            fail(at,
                 fmt::format("a bool needs a bit ('{}.00') or a T/C/TK flag", tag.address_text));
        auto f = to_memory_address(a, Access::bit);
        if (!f) fail(at, fmt::format("'{}': {}", tag.address_text, f.error().message()));
        tag.flag = true;
        tag.read_start = *f;
        tag.words = 1;
        check_model(at, tag, *f, 1);
        return;
    }
    if (!w) fail(at, fmt::format("'{}': {}", tag.address_text, w.error().message()));
    if (element_size(w->area_code) != 2)
        fail(at, fmt::format("'{}': area code {:02X} has no 2-byte words to read", tag.address_text,
                             w->area_code));
    if (tag.words > max_read_words)
        fail(at, fmt::format("tag '{}' needs {} words: more than one frame ({} words)", tag.name,
                             tag.words, max_read_words));
    tag.read_start = *w;
    check_model(at, tag, *w, tag.words);
    if (tag.writable && is_bool) {
        if (!to_memory_address(a, Access::bit))
            fail(at, fmt::format("'{}' cannot be written as a bit", tag.address_text));
    }
}

// The words [start, start+count) exist in this model and one segment of the table.
void Loader::check_model(const toml::node& at, const Tag& tag, MemoryAddress start,
                         std::size_t count) const {
    const auto* seg = find_segment(start.area_code, start.word);
    const auto last = static_cast<std::size_t>(start.word) + count - 1;
    if (seg == nullptr || last > seg->last_word)
        fail(at, fmt::format("tag '{}' ({} x {}) does not fit in its area", tag.name,
                             tag.address_text, count));
    if (!profile_->accepts(*seg))
        fail(at, fmt::format("'{}': the model {} has no {}", tag.address_text, profile_->name,
                             seg->name));
    const std::size_t index = seg->region_offset + (last - seg->first_word);
    if (auto size = region_size(*seg); index >= size)
        fail(at, fmt::format("'{}' x {} is beyond the {} of the model {} ({} words)",
                             tag.address_text, count, seg->name, profile_->name, size));
    if (tag.writable && !seg->allows(use_write))
        fail(at, fmt::format("tag '{}': {} cannot be written (W342 5-3-3)", tag.name, seg->name));
    if (tag.writable && start.word < seg->writable_from)
        fail(at, fmt::format("tag '{}': {} is read-only", tag.name, tag.address_text));
}

std::size_t Loader::region_size(const MemoryAreaSegment& seg) const {
    const auto& p = *profile_;
    switch (seg.region) {
        case Region::cio:
            return p.cio_words;
        case Region::work:
            return p.work_words;
        case Region::holding:
            return p.holding_words;
        case Region::auxiliary:
            return p.auxiliary_words;
        case Region::timer_counter:
            return 4096 + p.counters;
        case Region::dm:
            return p.dm_words;
        case Region::em:
            return seg.em_bank < p.em_banks ? p.em_bank_words : 0;
        case Region::em_current:
            return p.em_banks > 0 ? p.em_bank_words : 0;
        default:
            return 0x10000;  // the table's own bounds apply
    }
}

}  // namespace fins::bridge::detail
