#include "plc/injections.hpp"

#include <algorithm>
#include <string_view>

#include "fins/commands/diagnostics.hpp"
#include "plc/plc.hpp"

namespace fins::plc {
namespace {

bool ascii(std::string_view text) {
    return std::all_of(text.begin(), text.end(),
                       [](char c) { return static_cast<unsigned char>(c) < 0x80; });
}

std::string check_fal(const FalInjection& f, const std::string& field) {
    if (f.number == 0 || f.number > max_fal_number)
        return field + ".number: " + std::to_string(f.number) + " is not 1-511";
    if (f.message.size() > error_message_size) return field + ".message: longer than 16 characters";
    if (!ascii(f.message)) return field + ".message: not ASCII";
    return {};
}

bool is_fal_code(std::uint16_t code) {
    return (code >= 0x4101 && code <= 0x42FF) || (code >= 0xC101 && code <= 0xC2FF);
}

}  // namespace

std::string validate(const Injections& in) {
    for (std::size_t i = 0; i < in.fal.size(); ++i)
        if (auto e = check_fal(in.fal[i], "fal[" + std::to_string(i) + "]"); !e.empty()) return e;
    if (in.fals)
        if (auto e = check_fal(*in.fals, "fals"); !e.empty()) return e;
    for (std::size_t n = 0; n < in.messages.size(); ++n) {
        if (!in.messages[n]) continue;
        const std::string field = "messages[" + std::to_string(n) + "]";
        if (in.messages[n]->size() > msg_text_size) return field + ": longer than 32 characters";
        if (!ascii(*in.messages[n])) return field + ": not ASCII";
    }
    for (std::size_t i = 0; i < in.errors.size(); ++i) {
        const std::uint16_t code = in.errors[i];
        const std::string field = "errors[" + std::to_string(i) + "]";
        if (find_error_code(code) == nullptr) return field + ": not an error code of W342 5-3-27";
        if (is_fal_code(code)) return field + ": FAL/FALS codes go in fal / fals";
    }
    return {};
}

void apply(const Injections& in, Plc& plc, std::chrono::system_clock::time_point now) {
    auto& errors = plc.errors();
    if (in.battery_error) errors.set_battery_low(true, now);
    for (const auto& f : in.fal)
        if (check_fal(f, "fal").empty()) errors.raise_fal(f.number, f.message, now);
    if (in.fals && check_fal(*in.fals, "fals").empty())
        errors.raise_fals(in.fals->number, in.fals->message, now);
    for (std::size_t n = 0; n < in.messages.size(); ++n)
        if (in.messages[n] && ascii(*in.messages[n])) plc.messages().set(n, *in.messages[n]);
    for (const std::uint16_t code : in.errors)
        if (!is_fal_code(code)) errors.raise(code, now);
}

}  // namespace fins::plc
