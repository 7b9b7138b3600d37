// PLC address strings <-> Address <-> FINS memory addresses (W342 5-2-2).
#include "fins/address.hpp"
#include "codec/hex.hpp"
#include "fins/address_names.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace fins {
namespace {

Unexpected fail(AddressError e) {
    return Unexpected(make_error_code(e));
}

constexpr char upper(char c) noexcept {
    return (c >= 'a' && c <= 'z') ? char(c - 'a' + 'A') : c;
}
constexpr bool is_digit(char c) noexcept {
    return c >= '0' && c <= '9';
}

// Case-insensitive "does text start with prefix".
bool starts_with(std::string_view text, std::string_view prefix) noexcept {
    if (text.size() < prefix.size()) return false;
    for (std::size_t i = 0; i < prefix.size(); ++i)
        if (upper(text[i]) != prefix[i]) return false;
    return true;
}

// Above every limit of 5-2-2, so a long run of digits reports "out of range", not a wrap.
constexpr std::uint32_t saturate = 100000;

// Reads a run of decimal digits; nullopt when there is none.
std::optional<std::uint32_t> take_decimal(std::string_view& text) noexcept {
    std::size_t i = 0;
    std::uint32_t v = 0;
    while (i < text.size() && is_digit(text[i])) {
        v = std::min<std::uint32_t>(v * 10 + static_cast<std::uint32_t>(text[i] - '0'), saturate);
        ++i;
    }
    if (i == 0) return std::nullopt;
    text.remove_prefix(i);
    return v;
}

struct Prefix {
    std::string_view text;
    Area area;
    bool alias = false;  // another name of an area listed under its short name
};
// Longer prefixes first: "CIO" before "C", "DR" before "D". "E" is handled apart.
// DM, HR, WR, AR, TIM and CNT are the names CX-Programmer and the older manuals use for
// D, H, W, A, T and C: accepted as aliases (none is a prefix of another area's name
// followed by a digit), always printed the short way. Nothing else is: LR (CIO 1000-1199
// on CS/CJ) or SR name no single area of 5-2-2.
constexpr Prefix prefixes[] = {
    {"CIO", Area::cio},
    {"TIM", Area::timer, true},
    {"CNT", Area::counter, true},
    {"IR", Area::index_register},
    {"DR", Area::data_register},
    {"DM", Area::dm, true},
    {"HR", Area::holding, true},
    {"WR", Area::work, true},
    {"AR", Area::auxiliary, true},
    {"TK", Area::task_flag},
    {"W", Area::work},
    {"H", Area::holding},
    {"A", Area::auxiliary},
    {"T", Area::timer},
    {"C", Area::counter},
    {"D", Area::dm},
};

constexpr std::uint8_t max_bank = 0x18;
constexpr std::uint8_t max_bit = 15;

// Areas whose number names a whole register or flag, never a bit inside it.
bool is_bitless(Area area) noexcept {
    return area == Area::timer || area == Area::counter || area == Area::index_register ||
           area == Area::data_register || area == Area::task_flag;
}

std::string_view prefix_of(Area area) noexcept {
    switch (area) {
        case Area::cio:
            return "CIO";
        case Area::work:
            return "W";
        case Area::holding:
            return "H";
        case Area::auxiliary:
            return "A";
        case Area::timer:
            return "T";
        case Area::counter:
            return "C";
        case Area::dm:
            return "D";
        case Area::em:
        case Area::em_current:
            return "E";
        case Area::index_register:
            return "IR";
        case Area::data_register:
            return "DR";
        case Area::task_flag:
            return "TK";
    }
    return "?";
}

// Range checks shared by parse and to_memory_address (hand-built Addresses too).
std::error_code validate(const Address& a) noexcept {
    if (a.area == Area::em && a.bank > max_bank)
        return make_error_code(AddressError::bank_out_of_range);
    if (a.word > max_word(a.area)) return make_error_code(AddressError::word_out_of_range);
    if (a.bit) {
        if (is_bitless(a.area)) return make_error_code(AddressError::bit_not_allowed);
        if (*a.bit > max_bit) return make_error_code(AddressError::bit_out_of_range);
    }
    return {};
}

MemoryAddress make(std::uint8_t code, std::uint16_t word, std::uint8_t bit = 0) noexcept {
    return MemoryAddress{code, word, bit};
}

}  // namespace

std::uint16_t max_word(Area area) noexcept {
    switch (area) {
        case Area::cio:
            return 6143;
        case Area::work:
        case Area::holding:
            return 511;
        case Area::auxiliary:
            return 959;
        case Area::timer:
        case Area::counter:
            return 4095;
        case Area::dm:
        case Area::em:
        case Area::em_current:
            return 32767;
        case Area::index_register:
        case Area::data_register:
            return 15;
        case Area::task_flag:
            return 31;
    }
    return 0;
}

Result<Address> parse_address(std::string_view text) {
    if (text.empty()) return fail(AddressError::empty);
    Address a;
    std::string_view rest = text;
    if (is_digit(rest.front())) {
        a.area = Area::cio;  // a bare number is a CIO address: "10.13"
    } else if (upper(rest.front()) == 'E') {
        rest.remove_prefix(1);
        if (const auto underscore = rest.find('_'); underscore != std::string_view::npos) {
            // E<bank hex>_<word>: the bank is hexadecimal as in the manual (E10_5 = bank 0x10).
            const auto bank = rest.substr(0, underscore);
            if (bank.empty()) return fail(AddressError::bad_number);
            unsigned v = 0;
            for (char c : bank) {
                const int h = hex::digit_value(c);
                if (h < 0) return fail(AddressError::bad_number);
                v = std::min(v * 16 + static_cast<unsigned>(h), 0x100u);
            }
            if (v > max_bank) return fail(AddressError::bank_out_of_range);
            a.area = Area::em;
            a.bank = static_cast<std::uint8_t>(v);
            rest.remove_prefix(underscore + 1);
        } else {
            a.area = Area::em_current;
        }
    } else {
        const Prefix* found = nullptr;
        for (const auto& p : prefixes) {
            if (starts_with(rest, p.text)) {
                found = &p;
                break;
            }
        }
        if (!found) return fail(AddressError::unknown_area);
        a.area = found->area;
        rest.remove_prefix(found->text.size());
    }

    const auto word = take_decimal(rest);
    if (!word) return fail(AddressError::bad_number);
    if (*word > max_word(a.area)) return fail(AddressError::word_out_of_range);
    a.word = static_cast<std::uint16_t>(*word);

    if (!rest.empty() && rest.front() == '.') {
        rest.remove_prefix(1);
        if (is_bitless(a.area)) return fail(AddressError::bit_not_allowed);
        const auto bit = take_decimal(rest);
        if (!bit) return fail(AddressError::bad_number);
        if (*bit > max_bit) return fail(AddressError::bit_out_of_range);
        a.bit = static_cast<std::uint8_t>(*bit);
    }
    if (!rest.empty()) return fail(AddressError::trailing_characters);
    return a;
}

std::string area_names() {
    std::string names;
    std::string aliases;
    for (const auto& p : prefixes) {
        std::string& list = p.alias ? aliases : names;
        if (!list.empty()) list += ' ';
        list += p.text;
        if (!p.alias && p.area == Area::dm) list += " E";  // EM, parsed apart from the table
    }
    return names + " (also " + aliases + ")";
}

std::string format_address(const Address& a) {
    std::string out(prefix_of(a.area));
    if (a.area == Area::em) out += fmt::format("{:X}_", a.bank);
    out += fmt::format("{}", a.word);
    // Two digits, as Omron writes bit numbers (CIO 0.00 to 0.15 in W342 5-2-2, and
    // CX-Programmer): "CIO0.05", not "CIO0.5".
    if (a.bit) out += fmt::format(".{:02}", *a.bit);
    return out;
}

Result<MemoryAddress> to_memory_address(const Address& a, Access access) {
    if (auto ec = validate(a)) return Unexpected(ec);
    // Task flags have no word code: "TK2" itself names the flag.
    if (access == Access::natural)
        access = (a.bit || a.area == Area::task_flag) ? Access::bit : Access::word;
    if (access == Access::word && a.bit) return fail(AddressError::bit_not_allowed);
    const std::uint8_t bit = a.bit.value_or(0);

    // Word-addressed areas: {bit code, word code, bit+forced code, word+forced code}.
    struct Codes {
        std::uint8_t bit, word, bit_forced, word_forced;
    };
    std::optional<Codes> codes;
    switch (a.area) {
        case Area::cio:
            codes = Codes{0x30, 0xB0, 0x70, 0xF0};
            break;
        case Area::work:
            codes = Codes{0x31, 0xB1, 0x71, 0xF1};
            break;
        case Area::holding:
            codes = Codes{0x32, 0xB2, 0x72, 0xF2};
            break;
        case Area::auxiliary:
            codes = Codes{0x33, 0xB3, 0, 0};
            break;
        case Area::dm:
            codes = Codes{0x02, 0x82, 0, 0};
            break;
        case Area::em_current:
            codes = Codes{0x0A, 0x98, 0, 0};
            break;
        case Area::em: {
            const auto b = a.bank;
            codes = b < 0x10
                        ? Codes{std::uint8_t(0x20 + b), std::uint8_t(0xA0 + b), 0, 0}
                        : Codes{std::uint8_t(0xE0 + b - 0x10), std::uint8_t(0x60 + b - 0x10), 0, 0};
            break;
        }
        case Area::timer:
        case Area::counter: {
            // Counters sit 0x8000 words above timers in codes 09/49/89 (5-2-2).
            const auto word =
                static_cast<std::uint16_t>(a.area == Area::counter ? a.word + 0x8000 : a.word);
            if (access == Access::bit) return make(0x09, word);
            if (access == Access::forced) return make(0x49, word);
            return make(0x89, word);
        }
        case Area::task_flag:
            if (access == Access::word) return fail(AddressError::bit_required);
            if (access == Access::forced) return fail(AddressError::unknown_area);
            return make(0x06, a.word);
        case Area::index_register:
        case Area::data_register: {
            if (access == Access::bit) return fail(AddressError::bit_not_allowed);
            if (access == Access::forced) return fail(AddressError::unknown_area);
            const bool ir = a.area == Area::index_register;
            return make(ir ? 0xDC : 0xBC,
                        static_cast<std::uint16_t>((ir ? 0x0100 : 0x0200) + a.word));
        }
    }
    if (!codes) return fail(AddressError::unknown_area);
    switch (access) {
        case Access::word:
            return make(codes->word, a.word);
        case Access::bit:
            // A bit code without a bit number would silently read bit 0.
            if (!a.bit) return fail(AddressError::bit_required);
            return make(codes->bit, a.word, bit);
        case Access::forced:
            if (codes->bit_forced == 0) return fail(AddressError::unknown_area);
            return a.bit ? make(codes->bit_forced, a.word, bit) : make(codes->word_forced, a.word);
        case Access::natural:
            break;
    }
    return fail(AddressError::unknown_area);
}

}  // namespace fins
