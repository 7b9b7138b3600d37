// Fuzzes the value formats every front end prints with (typed/value_format.hpp, issue 25):
// memory words from the input, and the 65,536 word values 16 a run (all of them in one go
// are tests/typed/value_format_test.cpp's EveryWordOfEveryFormatPrintsValidJson), each
// printed in each format must give valid UTF-8 text and JSON that dumps without throwing
// and parses back; the input as a command-line value or a JSON value must parse or be
// refused without an exception, and what parses must print and parse back to the same
// words (NaN aside: its payload is not printed).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "fins/values.hpp"
#include "typed/value_format.hpp"

namespace {

using fins::typed::Format;
using Json = nlohmann::json;
using Words = std::vector<std::uint16_t>;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

// The strict dump throws on anything but valid UTF-8.
bool valid_utf8(std::string_view text) {
    try {
        (void)Json(std::string(text)).dump();
        return true;
    } catch (...) {
        return false;
    }
}

void check_utf8(const std::string& text) {
    check(valid_utf8(text));
}

void check_json(const Json& j) {
    std::string dumped;
    try {
        dumped = j.dump();
    } catch (...) {
        __builtin_trap();
    }
    const auto back = Json::parse(dumped, nullptr, false);
    check(!back.is_discarded());
}

bool is_nan(Format f, const Words& w) {
    if (f == Format::float32) return std::isnan(fins::words_to_float(w).value_or(0));
    if (f == Format::float64) return std::isnan(fins::words_to_double(w).value_or(0));
    return false;
}

// Prints `words` as `f`; every value's text is parsed back to the same words.
void print_and_reparse(Format f, const Words& words) {
    auto printed = fins::typed::print_words(f, words);
    if (!printed) {
        check(f == Format::bcd || f == Format::bcd32);  // only a non-BCD word is refused
        return;
    }
    const std::size_t step = fins::typed::words_per_value(f);
    for (std::size_t i = 0; i < printed->size(); ++i) {
        const auto& p = (*printed)[i];
        check_utf8(p.text);
        check_json(p.json);
        if (f == Format::string) {
            // Back to the words up to the first 00 byte.
            const std::string text = p.json.get<std::string>();
            auto again = fins::typed::parse_words(f, {text});
            check(std::holds_alternative<Words>(again));
            check(fins::words_to_string(std::get<Words>(again)) == text);
            check(fins::words_to_string(words) == text);
            continue;
        }
        if (f == Format::bits) continue;
        const Words one(words.begin() + static_cast<std::ptrdiff_t>(i * step),
                        words.begin() + static_cast<std::ptrdiff_t>((i + 1) * step));
        if (is_nan(f, one)) continue;
        auto again = fins::typed::parse_words(f, {p.text});
        check(std::holds_alternative<Words>(again) && std::get<Words>(again) == one);
        // The no-allocation JSON of the bridge is valid JSON too.
        std::string appended;
        fins::typed::append_json(appended, f, one);
        check(!Json::parse(appended, nullptr, false).is_discarded());
    }
}

// The sweep over every word value goes on from run to run, `per_run` values a run for every
// format (the whole 65,536 in one run took minutes under the fuzzer's instrumentation, far
// beyond CI's 20 s; tests/typed/ sweeps them all in one go, uninstrumented by libFuzzer).
void sweep_next_words() {
    constexpr std::uint32_t per_run = 16;
    static std::uint32_t next = 0;
    for (const Format f : fins::typed::all_formats()) {
        const std::size_t n = std::max<std::size_t>(fins::typed::words_per_value(f), 1);
        for (std::uint32_t w = next; w < next + per_run; ++w) {
            Words words(n, 0);
            for (std::size_t k = 0; k < n; ++k)
                words[k] = static_cast<std::uint16_t>(w * (2 * k + 1) + k * 0x9E37);
            print_and_reparse(f, words);
        }
    }
    next = (next + per_run) & 0xFFFF;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    sweep_next_words();
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    Words words;
    for (std::size_t i = 0; i + 1 < size; i += 2)
        words.push_back(static_cast<std::uint16_t>(data[i] << 8 | data[i + 1]));
    const auto json = Json::parse(input, nullptr, false);
    for (const Format f : fins::typed::all_formats()) {
        const std::size_t n = std::max<std::size_t>(fins::typed::words_per_value(f), 1);
        Words whole(words.begin(),
                    words.begin() + static_cast<std::ptrdiff_t>(words.size() / n * n));
        if (f == Format::string || !whole.empty()) print_and_reparse(f, whole);

        // The input as a typed value: words that print back to values of the format, or a
        // refusal whose sentence is valid UTF-8 when the input is.
        try {
            auto parsed = fins::typed::parse_words(f, {std::string(input)});
            if (auto* w = std::get_if<Words>(&parsed)) {
                if (f != Format::bits) print_and_reparse(f, *w);
                if (f == Format::string)
                    check(fins::words_to_string(*w) == input);  // valid Latin-1 text, no NUL
            } else if (valid_utf8(input)) {
                check_utf8(std::get<fins::typed::ParseError>(parsed).message);
            }
            if (!json.is_discarded() && f != Format::string) {
                std::array<std::uint16_t, 4> out{};
                auto why = fins::typed::json_to_words(f, json, out);
                if (why) check_utf8(*why);
            }
        } catch (...) {
            __builtin_trap();
        }
    }
    return 0;
}
