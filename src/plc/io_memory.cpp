// IoMemory: storage, direct access, forcing and address validation (locate).
// Element encodings and the 01 xx operations are in io_memory_access.cpp.
#include "plc/io_memory.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <string_view>
#include <utility>

namespace fins::plc {

namespace {

constexpr std::uint32_t bits_per_word = 16;

Unexpected fail(EndCode code) noexcept {
    return Unexpected(make_error_code(code));
}

// True when some segment of `code` that this model accepts is listed for `use`: decides
// between 1103 (known area, bad address) and 1101 (area not available to the command).
bool code_listed_for(std::uint8_t code, AreaUse use, const Profile& profile) noexcept {
    for (const auto& s : memory_area_table())
        if (s.code == code && s.allows(use) && profile.accepts(s)) return true;
    return false;
}

bool packed_bit(std::span<const std::uint16_t> words, std::uint32_t index) noexcept {
    const auto word = index / bits_per_word;
    if (word >= words.size()) return false;
    return ((unsigned{words[word]} >> (index % bits_per_word)) & 1U) != 0;
}

void set_packed_bit(std::span<std::uint16_t> words, std::uint32_t index, bool on) noexcept {
    const auto word = index / bits_per_word;
    if (word >= words.size()) return;
    const auto mask = static_cast<std::uint16_t>(1U << (index % bits_per_word));
    words[word] = static_cast<std::uint16_t>(on ? (words[word] | mask) : (words[word] & ~mask));
}

bool is_bit_forceable(Region region) noexcept {
    return region == Region::cio || region == Region::work || region == Region::holding;
}

}  // namespace

std::uint8_t element_bytes(ElementKind kind) noexcept {
    switch (kind) {
        case ElementKind::word:
            return 2;
        case ElementKind::word_forced:
            return 4;
        case ElementKind::double_word:
            return 4;
        case ElementKind::bit:
        case ElementKind::bit_forced:
        case ElementKind::flag:
        case ElementKind::flag_forced:
        case ElementKind::task_status:
            return 1;
    }
    return 1;
}

namespace {

constexpr std::array<WordRange, 5> retained_aux{{
    {100, 200},  // A100-A199 Error Log Area
    {300, 301},  // A300 Error Log Pointer
    {510, 521},  // A510-A520 Startup, Power Interruption, Operation Start/End Times, count
    {523, 524},  // A523 Total Power ON Time
    {720, 750},  // A720-A749 Power ON Clock Data 1-10
}};

// Zeroes `words` except the runs in `keep` (sorted, non-overlapping).
void clear_except(std::span<std::uint16_t> words, std::span<const WordRange> keep) noexcept {
    std::size_t from = 0;
    for (const auto& r : keep) {
        const auto first = std::min<std::size_t>(r.first, words.size());
        std::fill(words.begin() + static_cast<std::ptrdiff_t>(std::min(from, first)),
                  words.begin() + static_cast<std::ptrdiff_t>(first), std::uint16_t{0});
        from = std::max(from, std::min<std::size_t>(r.end, words.size()));
    }
    std::fill(words.begin() + static_cast<std::ptrdiff_t>(std::min(from, words.size())),
              words.end(), std::uint16_t{0});
}

std::span<std::uint16_t> take(Storage& storage, std::string_view name, std::size_t count,
                              Retention retention) {
    return storage.array<std::uint16_t>(name, count, retention);
}

}  // namespace

std::span<const WordRange> retained_auxiliary_words() noexcept {
    return retained_aux;
}

IoMemory::IoMemory(Profile profile, Storage& storage) : profile_(std::move(profile)) {
    profile_.timers = std::min(profile_.timers, max_timers);
    profile_.counters = std::min(profile_.counters, max_counters);
    // The 5-2-2 table addresses banks 00-18 (25 banks).
    profile_.em_banks = std::min<std::uint8_t>(profile_.em_banks, 0x19);
    constexpr auto R = Retention::retained;
    constexpr auto C = Retention::cleared;
    cio_ = take(storage, "io.cio", profile_.cio_words, C);
    cio_forced_ = take(storage, "io.cio.forced", profile_.cio_words, C);
    work_ = take(storage, "io.work", profile_.work_words, C);
    work_forced_ = take(storage, "io.work.forced", profile_.work_words, C);
    holding_ = take(storage, "io.holding", profile_.holding_words, R);
    holding_forced_ = take(storage, "io.holding.forced", profile_.holding_words, C);
    auxiliary_ = take(storage, "io.auxiliary", profile_.auxiliary_words, R);
    dm_ = take(storage, "io.dm", profile_.dm_words, R);
    em_ = take(storage, "io.em", std::size_t{profile_.em_banks} * profile_.em_bank_words, R);
    const auto tc = counter_base + profile_.counters;
    const auto flag_words = (tc + bits_per_word - 1) / bits_per_word;
    timer_counter_pv_ = take(storage, "io.tc.pv", tc, R);
    completion_flags_ = take(storage, "io.tc.flags", flag_words, R);
    completion_forced_ = take(storage, "io.tc.forced", flag_words, C);

    // Cleared parts of the partly retained sections: the timers (indexes below
    // counter_base; counter_base is a multiple of 16, so whole flag words) and A. Only
    // a restored state file holds anything there: fresh sections are zero already, and
    // clearing them would make their pages resident (10 KB a CPU Unit, issue 19).
    if (!storage.restored()) return;
    const WordRange counters{counter_base, tc};
    clear_except(timer_counter_pv_, std::span<const WordRange>(&counters, 1));
    const WordRange counter_flags{counter_base / bits_per_word, flag_words};
    clear_except(completion_flags_, std::span<const WordRange>(&counter_flags, 1));
    clear_except(auxiliary_, retained_aux);
}

std::span<std::uint16_t> IoMemory::words(Region region, std::uint8_t bank) noexcept {
    switch (region) {
        case Region::cio:
            return cio_;
        case Region::work:
            return work_;
        case Region::holding:
            return holding_;
        case Region::auxiliary:
            return auxiliary_;
        case Region::dm:
            return dm_;
        case Region::em:
            return em_bank(bank);
        case Region::em_current:
            return em_bank(current_em_bank_);
        case Region::timer_counter:
            return timer_counter_pv_;
        case Region::data_register:
            return data_registers_;
        default:
            return {};
    }
}

std::span<std::uint16_t> IoMemory::em_bank(std::uint8_t bank) noexcept {
    const std::size_t size = profile_.em_bank_words;
    if (bank >= profile_.em_banks || (std::size_t{bank} + 1) * size > em_.size()) return {};
    return em_.subspan(std::size_t{bank} * size, size);
}

std::span<const std::uint16_t> IoMemory::words(Region region, std::uint8_t bank) const noexcept {
    return const_cast<IoMemory*>(this)->words(region, bank);
}

std::span<std::uint16_t> IoMemory::forced_storage(Region region) noexcept {
    switch (region) {
        case Region::cio:
            return cio_forced_;
        case Region::work:
            return work_forced_;
        case Region::holding:
            return holding_forced_;
        default:
            return {};
    }
}

std::span<const std::uint16_t> IoMemory::forced_mask(Region region) const noexcept {
    return const_cast<IoMemory*>(this)->forced_storage(region);
}

bool IoMemory::completion_flag(std::uint32_t index) const noexcept {
    return packed_bit(completion_flags_, index);
}

void IoMemory::set_completion_flag(std::uint32_t index, bool on) noexcept {
    set_packed_bit(completion_flags_, index, on);
}

bool IoMemory::set_current_em_bank(std::uint8_t bank) noexcept {
    if (bank >= profile_.em_banks) return false;
    current_em_bank_ = bank;
    return true;
}

bool IoMemory::task_flag(std::uint32_t task) const noexcept {
    return task < task_count && ((task_flags_ >> task) & 1U) != 0;
}

void IoMemory::set_task_flag(std::uint32_t task, bool on) noexcept {
    if (task >= task_count) return;
    if (on)
        task_flags_ |= (1U << task);
    else
        task_flags_ &= ~(1U << task);
}

std::uint8_t IoMemory::task_status(std::uint32_t task) const noexcept {
    return task < task_count ? task_status_[task] : 0;
}

void IoMemory::set_task_status(std::uint32_t task, std::uint8_t status) noexcept {
    if (task < task_count) task_status_[task] = status;
}

bool IoMemory::force_bit(Region region, std::uint32_t word, std::uint8_t bit, bool on) noexcept {
    if (!is_bit_forceable(region) || bit >= bits_per_word) return false;
    auto values = words(region);
    auto forced = forced_storage(region);
    if (word >= values.size() || word >= forced.size()) return false;
    const auto index = word * bits_per_word + bit;
    set_packed_bit(values, index, on);
    set_packed_bit(forced, index, true);
    return true;
}

bool IoMemory::release_bit(Region region, std::uint32_t word, std::uint8_t bit) noexcept {
    if (!is_bit_forceable(region) || bit >= bits_per_word) return false;
    auto forced = forced_storage(region);
    if (word >= forced.size()) return false;
    set_packed_bit(forced, word * bits_per_word + bit, false);
    return true;
}

bool IoMemory::is_forced(Region region, std::uint32_t word, std::uint8_t bit) const noexcept {
    if (bit >= bits_per_word) return false;
    const auto forced = forced_mask(region);
    return word < forced.size() && packed_bit(forced, word * bits_per_word + bit);
}

bool IoMemory::force_completion_flag(std::uint32_t index, bool on) noexcept {
    if (index >= timer_counter_pv_.size()) return false;
    set_packed_bit(completion_flags_, index, on);
    set_packed_bit(completion_forced_, index, true);
    return true;
}

bool IoMemory::release_completion_flag(std::uint32_t index) noexcept {
    if (index >= timer_counter_pv_.size()) return false;
    set_packed_bit(completion_forced_, index, false);
    return true;
}

bool IoMemory::is_completion_flag_forced(std::uint32_t index) const noexcept {
    return packed_bit(completion_forced_, index);
}

void IoMemory::release_all_forced() noexcept {
    for (auto v : {cio_forced_, work_forced_, holding_forced_, completion_forced_})
        std::fill(v.begin(), v.end(), std::uint16_t{0});
}

// The storage indexes [first, end) around `index` that both the segment and the model
// have: the segment's range clipped to the region's size (timers and counters apart).
IoMemory::Window IoMemory::window(const MemoryAreaSegment& segment,
                                  std::uint32_t index) const noexcept {
    const std::uint32_t seg_first = segment.region_offset;
    const std::uint32_t seg_end =
        seg_first + static_cast<std::uint32_t>(segment.last_word - segment.first_word) + 1;
    Window model{0, std::numeric_limits<std::uint32_t>::max()};
    switch (segment.region) {
        case Region::timer_counter:
            model = index < counter_base ? Window{0, profile_.timers}
                                         : Window{counter_base, counter_base + profile_.counters};
            break;
        case Region::em_bank_number:
            model = {0, 1};
            break;
        case Region::task_flag:
            model = {0, task_count};
            break;
        case Region::index_register:
        case Region::data_register:
            model = {0, register_count};
            break;
        case Region::clock_pulse:
        case Region::condition_flag:
        case Region::access_error_flag:
            break;  // derived values: the segment decides
        default:
            model = {0, static_cast<std::uint32_t>(words(segment.region, segment.em_bank).size())};
    }
    return {std::max(seg_first, model.first), std::min(seg_end, model.end)};
}

bool IoMemory::writable(const MemoryAreaSegment& segment, std::uint16_t word,
                        std::uint32_t index) const noexcept {
    if (word < segment.writable_from) return false;
    switch (segment.region) {
        case Region::auxiliary:
            return index >= profile_.auxiliary_read_only_words;
        case Region::em_bank_number:
        case Region::task_flag:
        case Region::clock_pulse:
        case Region::condition_flag:
        case Region::access_error_flag:
            return false;
        default:
            return true;
    }
}

Result<ElementRange> IoMemory::locate(const MemoryAddress& start, std::uint32_t count, AreaUse use,
                                      Intent intent) const noexcept {
    const MemoryAreaSegment* segment = find_segment(start.area_code, start.word);
    if (segment == nullptr)
        return fail(code_listed_for(start.area_code, use, profile_)
                        ? EndCode::address_range_error
                        : EndCode::area_classification_missing);
    if (!segment->allows(use) || !profile_.accepts(*segment))
        return fail(EndCode::area_classification_missing);
    if (segment->region == Region::em_current && current_em_bank_ >= profile_.em_banks)
        return fail(EndCode::area_classification_missing);
    if (start.word < segment->first_word)  // find_segment contract, checked anyway
        return fail(EndCode::address_range_error);

    const bool bits = segment->bit_addressed();
    if (bits ? start.bit >= bits_per_word : start.bit != 0)
        return fail(EndCode::address_range_error);

    ElementRange range;
    range.segment = segment;
    range.region = segment->region;
    range.kind = segment->kind;
    range.bank = segment->region == Region::em_current ? current_em_bank_ : segment->em_bank;
    range.index =
        segment->region_offset + static_cast<std::uint32_t>(start.word - segment->first_word);
    range.bit = bits ? start.bit : std::uint8_t{0};
    range.count = count;

    const Window w = window(*segment, range.index);
    if (range.index < w.first || range.index >= w.end) return fail(EndCode::address_range_error);
    if (count > 0) {
        const std::uint64_t unit = bits ? bits_per_word : 1;
        const std::uint64_t first = (range.index - w.first) * unit + range.bit;
        const std::uint64_t capacity = std::uint64_t{w.end - w.first} * unit;
        if (first + count > capacity) return fail(EndCode::address_range_exceeded);
        if (intent == Intent::write && !writable(*segment, start.word, range.index))
            return fail(EndCode::read_only);
    }
    return range;
}

}  // namespace fins::plc
