// How a scenario reads and writes its tags' memory: the value types of `fins --as` on PLC
// words, straight on the words of word areas (resolved once at compile), else through
// IoMemory's element path. Writes keep forced bits, as a FINS 01 02 write does.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "fins/values.hpp"
#include "scenario/scenario_impl.hpp"

namespace fins::scenario {

namespace {

template <typename T>
T clamp_round(double v) {
    const double lo = static_cast<double>(std::numeric_limits<T>::min());
    const double hi = static_cast<double>(std::numeric_limits<T>::max());
    return static_cast<T>(std::llround(std::clamp(v, lo, hi)));
}

// Keeps the forced bits of `old` and takes the others from `value` (W342 5-3-4).
std::uint16_t merge_forced(std::uint16_t old, std::uint16_t value, std::uint16_t forced) {
    return static_cast<std::uint16_t>((value & ~forced) | (old & forced));
}

std::uint64_t pack(const std::uint16_t* words, unsigned n) {
    std::uint64_t raw = 0;
    for (unsigned i = 0; i < n; ++i)
        raw = (raw << 16) | words[i];
    return raw;
}

double decode(ValueType type, const std::array<std::uint16_t, 4>& words) {
    const Words w(words.data(), value_words(type));
    switch (type) {
        case ValueType::int16:
            return static_cast<std::int16_t>(words[0]);
        case ValueType::uint16:
            return words[0];
        case ValueType::int32:
            return words_to_int32(w).value_or(0);
        case ValueType::uint32:
            return words_to_uint32(w).value_or(0);
        case ValueType::float32:
            return static_cast<double>(words_to_float(w).value_or(0.0f));
        case ValueType::float64:
            return words_to_double(w).value_or(0.0);
        case ValueType::bcd: {
            // A word that is not BCD (a client wrote hex) reads as NaN: the tag is skipped.
            const auto v = words_to_bcd16(w);
            return v ? *v : std::nan("");
        }
        case ValueType::boolean:
            break;
    }
    return 0.0;
}

// `value` in the words of `type` (rounded and clamped); false for bool.
std::array<std::uint16_t, 4> encode(ValueType type, double value) {
    std::array<std::uint16_t, 4> words{};
    auto put = [&words](const auto& w) { std::copy(w.begin(), w.end(), words.begin()); };
    switch (type) {
        case ValueType::boolean:
            break;
        case ValueType::int16:
            put(int16_to_words(clamp_round<std::int16_t>(value)));
            break;
        case ValueType::uint16:
            words[0] = clamp_round<std::uint16_t>(value);
            break;
        case ValueType::bcd:
            words[0] = bcd16_to_words(
                           static_cast<std::uint16_t>(std::llround(std::clamp(value, 0.0, 9999.0))))
                           .value_or(std::array<std::uint16_t, 1>{})[0];
            break;
        case ValueType::int32:
            put(int32_to_words(clamp_round<std::int32_t>(value)));
            break;
        case ValueType::uint32:
            put(uint32_to_words(clamp_round<std::uint32_t>(value)));
            break;
        case ValueType::float32: {
            const double limit = static_cast<double>(std::numeric_limits<float>::max());
            put(float_to_words(static_cast<float>(std::clamp(value, -limit, limit))));
            break;
        }
        case ValueType::float64:
            put(double_to_words(value));
            break;
    }
    return words;
}

}  // namespace

void Scenario::Impl::bind_direct(Reference& reference) noexcept {
    const auto& r = reference.range;
    const bool bit = reference.type == ValueType::boolean;
    if (bit ? r.kind != ElementKind::bit : r.kind != ElementKind::word) return;
    if (r.region == Region::em_bank_number) return;
    auto& memory = plc->memory();
    const auto words = memory.words(r.region, r.bank);
    const std::size_t count = bit ? 1 : value_words(reference.type);
    if (std::size_t{r.index} + count > words.size()) return;
    reference.words = words.data() + r.index;
    const auto forced = std::as_const(memory).forced_mask(r.region);
    if (std::size_t{r.index} + count <= forced.size()) reference.forced = forced.data() + r.index;
    if (bit) reference.bit_mask = static_cast<std::uint16_t>(1U << r.bit);
}

double Scenario::Impl::read(const Reference& reference, std::uint64_t* raw) const noexcept {
    std::array<std::uint16_t, 4> words{};
    const unsigned n = value_words(reference.type);
    if (reference.words != nullptr) {
        if (reference.type == ValueType::boolean) {
            const bool on = (*reference.words & reference.bit_mask) != 0;
            if (raw != nullptr) *raw = on ? 1 : 0;
            return on ? 1.0 : 0.0;
        }
        std::copy_n(reference.words, n, words.begin());
    } else {
        std::array<std::uint8_t, 8> bytes{};
        ByteWriter out(bytes);
        plc->memory().read(reference.range, out, host_now);
        if (reference.type == ValueType::boolean) {
            if (raw != nullptr) *raw = bytes[0];
            return bytes[0] != 0 ? 1.0 : 0.0;
        }
        for (unsigned i = 0; i < n; ++i)
            words[i] = static_cast<std::uint16_t>((bytes[2 * i] << 8) | bytes[2 * i + 1]);
    }
    if (raw != nullptr) *raw = pack(words.data(), n);
    return decode(reference.type, words);
}

bool Scenario::Impl::write(TagState& tag, double value) noexcept {
    const Reference& reference = references[tag.reference];
    if (!std::isfinite(value)) return false;
    const bool bit = reference.type == ValueType::boolean;
    const bool on = value != 0.0;
    const unsigned n = value_words(reference.type);
    const auto words = encode(reference.type, value);
    if (reference.words != nullptr) {
        // The path of a FINS write on plain words: forced bits keep their forced state.
        // What memory holds after it (a forced bit may differ from what was asked) is
        // what the next tick compares with, to see a client's change and not the force.
        if (bit) {
            std::uint16_t& word = *reference.words;
            const std::uint16_t mask = reference.bit_mask;
            if (reference.forced == nullptr || (*reference.forced & mask) == 0)
                word = static_cast<std::uint16_t>(on ? (word | mask) : (word & ~mask));
            tag.last_raw = (word & mask) != 0 ? 1 : 0;
        } else {
            for (unsigned i = 0; i < n; ++i)
                reference.words[i] =
                    reference.forced == nullptr
                        ? words[i]
                        : merge_forced(reference.words[i], words[i], reference.forced[i]);
            tag.last_raw = pack(reference.words, n);
        }
    } else {
        std::array<std::uint8_t, 8> bytes{};
        std::size_t size = 1;
        if (bit) {
            bytes[0] = on ? 1 : 0;
        } else {
            for (unsigned i = 0; i < n; ++i) {
                bytes[2 * i] = static_cast<std::uint8_t>(words[i] >> 8);
                bytes[2 * i + 1] = static_cast<std::uint8_t>(words[i]);
            }
            size = 2 * n;
        }
        plc->memory().write(reference.range, Bytes(bytes.data(), size));
        read(reference, &tag.last_raw);
    }
    tag.written = true;
    return true;
}

}  // namespace fins::scenario
