// IoMemory element operations: the encodings of W342 5-2-1 "Element Data
// Configurations" and the semantics of 01 02 WRITE, 01 03 FILL and 01 05 TRANSFER.
#include <array>
#include <vector>

#include "plc/io_memory.hpp"
#include "plc/scan_cycle.hpp"

namespace fins::plc {

namespace {

constexpr std::uint32_t bits_per_word = 16;

// Keeps the forced bits of `old` and takes the others from `value`.
constexpr std::uint16_t merge_forced(std::uint16_t old, std::uint16_t value,
                                     std::uint16_t forced) noexcept {
    return static_cast<std::uint16_t>((value & ~forced) | (old & forced));
}

}  // namespace

bool IoMemory::clock_pulse(ClockPulse pulse, TimePoint now) noexcept {
    // Periods in microseconds: 1 min, 1 s, 0.2 s, 0.1 s, 0.02 s (W342 5-2-2, area 07).
    static constexpr std::array<std::int64_t, clock_pulse_count> periods{60'000'000, 1'000'000,
                                                                         200'000, 100'000, 20'000};
    const auto i = static_cast<std::size_t>(pulse);
    if (i >= periods.size()) return false;
    const auto period = periods[i];
    const auto us =
        std::chrono::duration_cast<std::chrono::microseconds>(now.time_since_epoch()).count();
    const auto phase = ((us % period) + period) % period;  // also before the epoch
    return phase < period / 2;
}

bool IoMemory::condition_flag(ConditionFlag flag) noexcept {
    return flag == ConditionFlag::always_on;
}

bool IoMemory::bit_at(const ElementRange& r, std::uint64_t position) const noexcept {
    const auto values = words(r.region, r.bank);
    const auto word = position / bits_per_word;
    if (word >= values.size()) return false;
    return ((unsigned{values[word]} >> (position % bits_per_word)) & 1U) != 0;
}

bool IoMemory::bit_forced_at(const ElementRange& r, std::uint64_t position) const noexcept {
    const auto forced = forced_mask(r.region);
    const auto word = position / bits_per_word;
    if (word >= forced.size()) return false;
    return ((unsigned{forced[word]} >> (position % bits_per_word)) & 1U) != 0;
}

void IoMemory::store_bit(const ElementRange& r, std::uint64_t position, bool on) noexcept {
    if (bit_forced_at(r, position)) return;
    auto values = words(r.region, r.bank);
    const auto word = position / bits_per_word;
    if (word >= values.size()) return;
    const auto mask = static_cast<std::uint16_t>(1U << (position % bits_per_word));
    values[word] = static_cast<std::uint16_t>(on ? (values[word] | mask) : (values[word] & ~mask));
}

std::uint16_t IoMemory::word_at(const ElementRange& r, std::uint32_t index) const noexcept {
    if (r.region == Region::em_bank_number) return current_em_bank_;
    const auto values = words(r.region, r.bank);
    return index < values.size() ? values[index] : std::uint16_t{0};
}

void IoMemory::store_word(const ElementRange& r, std::uint32_t index,
                          std::uint16_t value) noexcept {
    auto values = words(r.region, r.bank);
    if (index >= values.size()) return;
    const auto forced = forced_mask(r.region);
    const std::uint16_t mask = index < forced.size() ? forced[index] : std::uint16_t{0};
    values[index] = merge_forced(values[index], value, mask);
}

std::uint8_t IoMemory::flag_at(const ElementRange& r, std::uint32_t index,
                               TimePoint now) const noexcept {
    switch (r.region) {
        case Region::timer_counter: {
            const bool forced =
                r.kind == ElementKind::flag_forced && is_completion_flag_forced(index);
            return static_cast<std::uint8_t>((completion_flag(index) ? 1U : 0U) |
                                             (forced ? 2U : 0U));
        }
        case Region::task_flag:
            return r.kind == ElementKind::task_status ? task_status(index)
                                                      : static_cast<std::uint8_t>(task_flag(index));
        // Area 07 comes from the scan cycle's time base: values refreshed at the start of
        // the cycle in progress (scan_cycle.hpp).
        case Region::clock_pulse:
            return index < clock_pulse_count &&
                   ScanCycle::clock_pulse(profile_, static_cast<ClockPulse>(index), now);
        case Region::condition_flag:
            return index < bits_per_word &&
                   ScanCycle::condition_flag(static_cast<ConditionFlag>(index));
        case Region::access_error_flag:
            return access_error_flag_ ? 1 : 0;
        default:
            return 0;
    }
}

void IoMemory::read(const ElementRange& r, ByteWriter& out, TimePoint now) const noexcept {
    switch (r.kind) {
        case ElementKind::bit:
        case ElementKind::bit_forced: {
            std::uint64_t position = std::uint64_t{r.index} * bits_per_word + r.bit;
            for (std::uint32_t i = 0; i < r.count; ++i, ++position) {
                // 00/01; with forced status bit 0 = value, bit 1 = forced.
                unsigned v = bit_at(r, position) ? 1U : 0U;
                if (r.kind == ElementKind::bit_forced && bit_forced_at(r, position)) v |= 2U;
                out.u8(static_cast<std::uint8_t>(v));
            }
            break;
        }
        case ElementKind::word:
            for (std::uint32_t i = 0; i < r.count; ++i)
                out.u16(word_at(r, r.index + i));
            break;
        case ElementKind::word_forced: {
            // Forced-bit mask word first, then the value word (UNCONFIRMED order, see
            // fins/memory_area.hpp).
            const auto forced = forced_mask(r.region);
            for (std::uint32_t i = 0; i < r.count; ++i) {
                const auto index = r.index + i;
                out.u16(index < forced.size() ? forced[index] : std::uint16_t{0});
                out.u16(word_at(r, index));
            }
            break;
        }
        case ElementKind::double_word:
            for (std::uint32_t i = 0; i < r.count; ++i) {
                const auto index = r.index + i;
                out.u32(r.region == Region::index_register && index < register_count
                            ? index_registers_[index]
                            : 0U);
            }
            break;
        case ElementKind::flag:
        case ElementKind::flag_forced:
        case ElementKind::task_status:
            for (std::uint32_t i = 0; i < r.count; ++i)
                out.u8(flag_at(r, r.index + i, now));
            break;
    }
}

EndCode IoMemory::write(const ElementRange& r, Bytes data) noexcept {
    if (data.size() != r.byte_size()) return EndCode::elements_data_mismatch;
    ByteReader in(data);
    switch (r.kind) {
        case ElementKind::bit: {
            // The manual defines 00 OFF / 01 ON; any other non-zero byte is taken as ON.
            std::uint64_t position = std::uint64_t{r.index} * bits_per_word + r.bit;
            for (std::uint32_t i = 0; i < r.count; ++i, ++position)
                store_bit(r, position, in.u8() != 0);
            return EndCode::normal_completion;
        }
        case ElementKind::word:
            if (r.region == Region::em_bank_number) return EndCode::read_only;
            for (std::uint32_t i = 0; i < r.count; ++i)
                store_word(r, r.index + i, in.u16());
            return EndCode::normal_completion;
        case ElementKind::double_word:
            if (r.region != Region::index_register) return EndCode::area_classification_missing;
            for (std::uint32_t i = 0; i < r.count; ++i) {
                const auto value = in.u32();
                if (r.index + i < register_count) index_registers_[r.index + i] = value;
            }
            return EndCode::normal_completion;
        case ElementKind::flag:
            if (r.region != Region::timer_counter) return EndCode::read_only;
            for (std::uint32_t i = 0; i < r.count; ++i) {
                const bool on = in.u8() != 0;
                if (!is_completion_flag_forced(r.index + i)) set_completion_flag(r.index + i, on);
            }
            return EndCode::normal_completion;
        default:
            // Forced-status and task-status forms are read-only encodings.
            return EndCode::area_classification_missing;
    }
}

EndCode IoMemory::fill(const ElementRange& r, std::uint16_t value) noexcept {
    if (r.kind != ElementKind::word || r.region == Region::em_bank_number)
        return EndCode::area_classification_missing;
    for (std::uint32_t i = 0; i < r.count; ++i) {
        store_word(r, r.index + i, value);
        // W342 5-3-4: filling T/C PVs turns the Completion Flags OFF (forced ones stay).
        if (r.region == Region::timer_counter && !is_completion_flag_forced(r.index + i))
            set_completion_flag(r.index + i, false);
    }
    return EndCode::normal_completion;
}

EndCode IoMemory::transfer(const ElementRange& source, const ElementRange& destination) {
    if (source.kind != ElementKind::word || destination.kind != ElementKind::word ||
        destination.region == Region::em_bank_number)
        return EndCode::area_classification_missing;
    if (source.count != destination.count) return EndCode::elements_data_mismatch;
    // Snapshot first: the ranges may overlap (same region, or an EM bank and the
    // current bank naming the same storage).
    std::vector<std::uint16_t> copy(source.count);
    for (std::uint32_t i = 0; i < source.count; ++i)
        copy[i] = word_at(source, source.index + i);
    for (std::uint32_t i = 0; i < destination.count; ++i)
        store_word(destination, destination.index + i, copy[i]);
    return EndCode::normal_completion;
}

}  // namespace fins::plc
