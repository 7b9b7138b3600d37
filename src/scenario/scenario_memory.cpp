// How a scenario reads and writes its tags' memory: the value types of `fins --as` on PLC
// words, on the image of the words of word areas (laid out once at compile, copied in and
// out around each tick), else through IoMemory's element path. Writes keep forced bits,
// as a FINS 01 02 write does.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "fins/values.hpp"
#include "scenario/scenario_impl.hpp"

namespace fins::scenario {

namespace {

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
    reference.memory = words.data() + r.index;
    const auto forced = std::as_const(memory).forced_mask(r.region);
    if (std::size_t{r.index} + count <= forced.size())
        reference.memory_forced = forced.data() + r.index;
    if (bit) reference.bit_mask = static_cast<std::uint16_t>(1U << r.bit);
}

void Scenario::Impl::build_image() {
    // The directly accessed words of every reference, by area and index; overlapping or
    // adjacent ones of one area merge into a run, so that references sharing words share
    // them in the image too (a link reading D100 sees what the tag on D100 wrote).
    struct Span {
        std::uint32_t reference;
        std::uint32_t end;  // index past the last word
    };
    std::vector<Span> spans;
    offloadable = true;
    for (std::uint32_t i = 0; i < references.size(); ++i) {
        const Reference& r = references[i];
        if (r.memory == nullptr) {
            offloadable = false;
            continue;
        }
        const unsigned count = r.type == ValueType::boolean ? 1 : value_words(r.type);
        spans.push_back({i, r.range.index + count});
    }
    const auto area = [this](const Span& s) {
        const auto& r = references[s.reference].range;
        return std::pair{static_cast<unsigned>(r.region), r.bank};
    };
    std::sort(spans.begin(), spans.end(), [&](const Span& a, const Span& b) {
        const auto ka = area(a), kb = area(b);
        if (ka != kb) return ka < kb;
        return references[a.reference].range.index < references[b.reference].range.index;
    });
    // First pass: the runs (start index, end index, first span); then the image.
    struct Pending {
        std::size_t first, last;  // spans
        std::uint32_t start, end;
    };
    std::vector<Pending> merged;
    for (std::size_t i = 0; i < spans.size(); ++i) {
        const std::uint32_t start = references[spans[i].reference].range.index;
        if (!merged.empty() && area(spans[merged.back().first]) == area(spans[i]) &&
            start <= merged.back().end) {
            merged.back().end = std::max(merged.back().end, spans[i].end);
            merged.back().last = i;
            continue;
        }
        merged.push_back({i, i, start, spans[i].end});
    }
    std::uint32_t total = 0;
    for (const auto& p : merged)
        total += p.end - p.start;
    image.assign(total, 0);
    image_before.assign(total, 0);
    image_forced.assign(total, 0);
    runs.clear();
    std::uint32_t offset = 0;
    for (const auto& p : merged) {
        const Reference& first = references[spans[p.first].reference];
        const std::uint32_t back = first.range.index - p.start;  // 0: spans are sorted
        ImageRun run{first.memory - back, nullptr, offset, p.end - p.start};
        bool forced = true;
        for (std::size_t i = p.first; i <= p.last; ++i)
            forced = forced && references[spans[i].reference].memory_forced != nullptr;
        if (forced) run.forced = first.memory_forced - back;
        for (std::size_t i = p.first; i <= p.last; ++i) {
            Reference& r = references[spans[i].reference];
            const std::uint32_t at = offset + (r.range.index - p.start);
            r.words = image.data() + at;
            r.forced = forced ? image_forced.data() + at : nullptr;
        }
        runs.push_back(run);
        offset += run.size;
    }
}

void Scenario::Impl::bind_words() noexcept {
    auto one_word = [](const Reference& r) {
        return r.words != nullptr && (r.type == ValueType::int16 || r.type == ValueType::uint16);
    };
    for (auto& in : code) {
        if (in.op != Expression::Op::load) continue;
        const Reference& r = references[in.argument];
        if (!one_word(r)) continue;
        in.op =
            r.type == ValueType::int16 ? Expression::Op::load_int16 : Expression::Op::load_uint16;
        in.argument = static_cast<std::uint32_t>(r.words - image.data());
    }
    for (auto& tag : tags) {
        const Reference& r = references[tag.reference];
        if (!one_word(r) || r.forced != nullptr) continue;
        tag.word = static_cast<std::uint32_t>(r.words - image.data());
        tag.word_signed = r.type == ValueType::int16;
    }
}

void Scenario::Impl::gather() noexcept {
    for (const auto& run : runs) {
        std::copy_n(run.memory, run.size, image.data() + run.offset);
        if (run.forced != nullptr)
            std::copy_n(run.forced, run.size, image_forced.data() + run.offset);
    }
    if (concurrent) std::copy(image.begin(), image.end(), image_before.begin());
}

void Scenario::Impl::scatter() noexcept {
    for (const auto& run : runs) {
        const std::uint16_t* now = image.data() + run.offset;
        if (!concurrent) {
            // Nothing else ran since gather(): memory still holds what the image started
            // from, and a word the tick changed differs from it.
            for (std::uint32_t i = 0; i < run.size; ++i)
                if (now[i] != run.memory[i])
                    run.memory[i] = run.forced == nullptr
                                        ? now[i]
                                        : merge_forced(run.memory[i], now[i], run.forced[i]);
            continue;
        }
        const std::uint16_t* before = image_before.data() + run.offset;
        for (std::uint32_t i = 0; i < run.size; ++i) {
            // Unchanged by the tick, or changed by a client since begin_tick (its write
            // wins; a stateful tag adopts it next tick): left as memory has it.
            if (now[i] == before[i] || run.memory[i] != before[i]) continue;
            run.memory[i] =
                run.forced == nullptr ? now[i] : merge_forced(run.memory[i], now[i], run.forced[i]);
        }
    }
}

double Scenario::Impl::read_own(const TagState& tag, std::uint64_t& raw) const noexcept {
    if (tag.word == TagState::no_word) return read(references[tag.reference], &raw);
    const std::uint16_t w = image[tag.word];
    raw = w;
    return tag.word_signed ? static_cast<double>(static_cast<std::int16_t>(w))
                           : static_cast<double>(w);
}

double Scenario::Impl::read(const Reference& reference, std::uint64_t* raw) const noexcept {
    std::array<std::uint16_t, 4> words{};
    const unsigned n = value_words(reference.type);
    if (reference.words != nullptr) {
        switch (reference.type) {
            case ValueType::boolean: {
                const bool on = (*reference.words & reference.bit_mask) != 0;
                if (raw != nullptr) *raw = on ? 1 : 0;
                return on ? 1.0 : 0.0;
            }
            case ValueType::int16:  // the common one-word types: no decode
                if (raw != nullptr) *raw = *reference.words;
                return static_cast<std::int16_t>(*reference.words);
            case ValueType::uint16:
                if (raw != nullptr) *raw = *reference.words;
                return *reference.words;
            default:
                break;
        }
        for (unsigned i = 0; i < n; ++i)
            words[i] = reference.words[i];
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

bool Scenario::Impl::write_reference(TagState& tag, double value) noexcept {
    const Reference& reference = references[tag.reference];
    const bool bit = reference.type == ValueType::boolean;
    const bool on = value != 0.0;
    const unsigned n = value_words(reference.type);
    const auto words = encode(reference.type, value);
    if (reference.words != nullptr) {
        // The path of a FINS write on plain words: forced bits keep their forced state.
        // What the image holds after it (a forced bit may differ from what was asked) is
        // what the next tick compares with, to see a client's change and not the force.
        if (bit) {
            std::uint16_t& word = *reference.words;
            const std::uint16_t mask = reference.bit_mask;
            if (reference.forced == nullptr || (*reference.forced & mask) == 0)
                word = static_cast<std::uint16_t>(on ? (word | mask) : (word & ~mask));
            if (tag.adopts) tag.last_raw = (word & mask) != 0 ? 1 : 0;
        } else {
            for (unsigned i = 0; i < n; ++i)
                reference.words[i] =
                    reference.forced == nullptr
                        ? words[i]
                        : merge_forced(reference.words[i], words[i], reference.forced[i]);
            if (tag.adopts) tag.last_raw = pack(reference.words, n);
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
        if (tag.adopts) {
            std::uint64_t raw = 0;
            read(reference, &raw);
            tag.last_raw = raw;
        }
    }
    tag.written = true;
    return true;
}

}  // namespace fins::scenario
