#include "plc/parameter_areas.hpp"

#include <algorithm>

namespace fins::plc {

namespace {

Unexpected fail(EndCode e) {
    return Unexpected(make_error_code(e));
}

// Where the I/O table sits inside the 8000 range.
const ParameterAreaInfo& io_table_info() noexcept {
    return *find_parameter_area(parameter_area_io_table);
}

// Does [start, start + count) of `area` touch I/O table words?
bool touches_io_table(const ParameterAreaInfo& area, std::uint32_t start,
                      std::uint32_t count) noexcept {
    if (count == 0) return false;
    if (area.code == parameter_area_io_table) return true;
    if (area.code != parameter_area_all) return false;
    const auto& io = io_table_info();
    const std::uint32_t first = start;
    const std::uint32_t last = start + count - 1;
    return first < std::uint32_t{io.offset} + io.words && last >= io.offset;
}

ParameterRange make_range(const ParameterAreaInfo& area, std::uint16_t start,
                          std::uint32_t count) noexcept {
    ParameterRange range;
    range.area = &area;
    range.start = start;
    range.count = static_cast<std::uint16_t>(count);
    range.includes_last = count != 0 && std::uint32_t{start} + count == area.words;
    range.io_table = touches_io_table(area, start, count);
    return range;
}

}  // namespace

ParameterAreas::ParameterAreas(const Profile&, Storage& storage)
    : all_(storage.array<std::uint16_t>("parameter_areas", parameter_area_all_words,
                                        Retention::retained)),
      staged_(storage.array<std::uint16_t>("parameter_areas_staged", parameter_area_all_words,
                                           Retention::cleared)),
      staging_(storage.object<Staging>("parameter_areas_staging", Retention::cleared)) {}

std::span<std::uint16_t> ParameterAreas::words(std::uint16_t area_code) noexcept {
    const auto* area = find_parameter_area(area_code);
    if (area == nullptr) return {};
    return all_.subspan(area->offset, area->words);
}

std::span<const std::uint16_t> ParameterAreas::words(std::uint16_t area_code) const noexcept {
    const auto* area = find_parameter_area(area_code);
    if (area == nullptr) return {};
    return std::span<const std::uint16_t>(all_).subspan(area->offset, area->words);
}

// W342 5-3-7.
Result<ParameterReadPlan> ParameterAreas::plan_read(const ParameterAreaRead& command) const {
    const auto* area = find_parameter_area(command.area);
    if (area == nullptr) return fail(EndCode::area_classification_missing);
    // "Bit 15 must be OFF (0) in the command format."
    if (command.last_word) return fail(EndCode::parameter_error);
    if (command.start >= area->words) return fail(EndCode::address_range_error);
    ParameterReadPlan plan;
    std::uint32_t count = command.count;
    if (count > max_parameter_words) {
        count = max_parameter_words;
        plan.code = EndCode::response_too_long;
    }
    const std::uint32_t left = area->words - command.start;
    if (count > left) {
        count = left;
        plan.code = EndCode::address_range_exceeded;
    }
    plan.range = make_range(*area, command.start, count);
    return plan;
}

// W342 5-3-8.
Result<ParameterRange> ParameterAreas::plan_write(const ParameterAreaWrite& command) const {
    const auto* area = find_parameter_area(command.area);
    if (area == nullptr) return fail(EndCode::area_classification_missing);
    if (command.start >= area->words) return fail(EndCode::address_range_error);
    // "Nothing will be written if more than 498 words are specified."
    if (command.count > max_parameter_words) return fail(EndCode::command_too_long);
    if (std::uint32_t{command.start} + command.count > area->words)
        return fail(EndCode::address_range_exceeded);
    if (command.data.size() != std::size_t{command.count} * 2)
        return fail(EndCode::elements_data_mismatch);
    auto range = make_range(*area, command.start, command.count);
    // "If the number of write words is set to 0000, no words will be written and a
    // normal end code will be returned", whatever bit 15 says.
    if (command.count != 0 && range.includes_last != command.last_word)
        return fail(EndCode::parameter_error);
    return range;
}

// W342 5-3-9.
Result<ParameterRange> ParameterAreas::plan_clear(const ParameterAreaClear& command) const {
    const auto* area = find_parameter_area(command.area);
    if (area == nullptr) return fail(EndCode::area_classification_missing);
    if (command.start != 0) return fail(EndCode::address_range_error);
    if (command.value != 0) return fail(EndCode::parameter_error);
    if (command.count == 0) return make_range(*area, 0, 0);
    if (command.count > area->words) return fail(EndCode::address_range_exceeded);
    if (command.count < area->words) return fail(EndCode::parameter_error);
    return make_range(*area, 0, area->words);
}

void ParameterAreas::read(const ParameterRange& range, ByteWriter& out) const noexcept {
    if (range.area == nullptr) return;
    const auto words = all_.subspan(std::size_t{range.area->offset} + range.start, range.count);
    for (auto word : words)
        out.u16(word);
}

EndCode ParameterAreas::write(const ParameterRange& range, Bytes data) noexcept {
    if (range.area == nullptr || range.count == 0) return EndCode::normal_completion;
    const auto& area = *range.area;
    const std::size_t base = std::size_t{area.offset} + range.start;
    ByteReader r(data);
    if (!area.whole_area) {
        for (std::size_t i = 0; i < range.count; ++i)
            all_[base + i] = r.u16();
        return EndCode::normal_completion;
    }
    if (range.start == 0) {
        staging_ = Staging{area.code, 0};
    } else if (staging_.area != area.code || staging_.next != range.start) {
        staging_ = Staging{};
        return EndCode::parameter_error;
    }
    for (std::size_t i = 0; i < range.count; ++i)
        staged_[base + i] = r.u16();
    staging_.next = static_cast<std::uint16_t>(range.start + range.count);
    if (range.includes_last) {
        std::copy_n(staged_.begin() + area.offset, area.words, all_.begin() + area.offset);
        staging_ = Staging{};
    }
    return EndCode::normal_completion;
}

void ParameterAreas::clear(const ParameterRange& range) noexcept {
    if (range.area == nullptr || range.count == 0) return;
    std::fill_n(all_.begin() + range.area->offset + range.start, range.count, std::uint16_t{0});
    staging_ = Staging{};
}

}  // namespace fins::plc
