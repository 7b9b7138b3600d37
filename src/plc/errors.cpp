#include "plc/errors.hpp"

#include <algorithm>
#include <array>

#include "fins/commands/diagnostics.hpp"
#include "plc/clock.hpp"

namespace fins::plc {
namespace {

bool is_fal_or_fals(std::uint16_t code) noexcept {
    return (code >= 0x4101 && code <= 0x42FF) || (code >= 0xC101 && code <= 0xC2FF);
}

// Higher rank = more serious: table order, then the newest occurrence.
bool more_serious(const ActiveError& a, const ActiveError& b) noexcept {
    if (a.priority != b.priority) return a.priority < b.priority;
    return a.sequence > b.sequence;
}

}  // namespace

ErrorState::ErrorState(const Profile&, Storage& storage)
    : state_(storage.object<Present>("errors.present", Retention::cleared)),
      log_(storage.object<Log>("errors.log", Retention::retained)) {
    // A restored or damaged state file must not index past the records.
    if (log_.count > log_max_records) log_.count = log_max_records;
    if (state_.count > max_active_errors) state_.count = 0;
    recompute();
}

bool ErrorState::raise(std::uint16_t code, TimePoint now, std::string_view message,
                       std::uint16_t detail) {
    const ErrorCodeInfo* info = find_error_code(code);
    if (info == nullptr || message.size() > 16) return false;
    ActiveError* slot = nullptr;
    for (std::uint32_t i = 0; i < state_.count; ++i)
        if (state_.items[i].code == code) slot = &state_.items[i];
    const bool fresh = slot == nullptr;
    if (fresh) {
        if (state_.count >= max_active_errors) return false;
        slot = &state_.items[state_.count++];
        *slot = ActiveError{};
        slot->code = code;
        slot->detail = detail;
        slot->sequence = ++state_.sequence;
        slot->priority = static_cast<std::uint8_t>(info - error_code_table().data());
    }
    std::fill(slot->message.begin(), slot->message.end(), '\0');
    std::copy(message.begin(), message.end(), slot->message.begin());
    slot->message_size = static_cast<std::uint8_t>(message.size());
    if (fresh) append_log(code, detail, now);
    recompute();
    return true;
}

bool ErrorState::raise_fal(std::uint16_t number, std::string_view message, TimePoint now) {
    if (number == 0 || number > max_fal_number) return false;
    return raise(static_cast<std::uint16_t>(fal_code_base + number), now, message);
}

bool ErrorState::raise_fals(std::uint16_t number, std::string_view message, TimePoint now) {
    if (number == 0 || number > max_fal_number) return false;
    return raise(static_cast<std::uint16_t>(fals_code_base + number), now, message);
}

void ErrorState::set_battery_cause(std::uint8_t cause, bool low, TimePoint now) {
    state_.battery_low =
        static_cast<std::uint8_t>(low ? state_.battery_low | cause : state_.battery_low & ~cause);
    if (low)
        raise(battery_error_code, now);
    else if (!battery_low())
        clear(battery_error_code, now);
}

bool ErrorState::clear(std::uint16_t code, TimePoint now) {
    bool found = false;
    for (std::uint32_t i = 0; i < state_.count; ++i) {
        if (state_.items[i].code != code) continue;
        state_.items[i] = state_.items[state_.count - 1];
        --state_.count;
        found = true;
        break;
    }
    recompute();
    // 5-3-27: "the same error will immediately occur again" while its cause remains.
    if (found && code == battery_error_code && battery_low()) raise(code, now);
    return found;
}

void ErrorState::clear_all(TimePoint now) {
    state_.count = 0;
    recompute();
    if (battery_low()) raise(battery_error_code, now);
}

bool ErrorState::is_active(std::uint16_t code) const noexcept {
    return std::any_of(active().begin(), active().end(),
                       [code](const ActiveError& e) { return e.code == code; });
}

const ActiveError* ErrorState::most_serious() const noexcept {
    const ActiveError* best = nullptr;
    for (const auto& e : active())
        if (best == nullptr || more_serious(e, *best)) best = &e;
    return best;
}

std::string_view ErrorState::status_message() const noexcept {
    const ActiveError* best = nullptr;
    for (const auto& e : active())
        if (is_fal_or_fals(e.code) && (best == nullptr || more_serious(e, *best))) best = &e;
    return best != nullptr ? best->text() : std::string_view{};
}

std::optional<std::string_view> ErrorState::fal_message(std::uint16_t number) const noexcept {
    if (number == 0 || number > max_fal_number) return std::nullopt;
    const auto fals = static_cast<std::uint16_t>(fals_code_base + number);
    const auto fal = static_cast<std::uint16_t>(fal_code_base + number);
    const ActiveError* found = nullptr;
    for (const auto& e : active()) {
        if (e.code == fals) return e.text();
        if (e.code == fal) found = &e;
    }
    if (found != nullptr) return found->text();
    return std::nullopt;
}

void ErrorState::append_log(std::uint16_t code, std::uint16_t detail, TimePoint now) noexcept {
    if (log_.count >= log_max_records) {
        // Full: the oldest record goes, the rest move down (A100-A199 behaviour).
        std::copy(log_.records.begin() + 1, log_.records.end(), log_.records.begin());
        log_.count = log_max_records - 1;
    }
    const LogTime time = clock_ != nullptr ? to_log_time(clock_->read(now)) : to_log_time(now);
    log_.records[log_.count++] = ErrorLogRecord{code, detail, time};
}

void ErrorState::recompute() noexcept {
    std::uint16_t fatal = 0;
    std::uint16_t non_fatal = 0;
    bool any_fatal = false;
    bool any_non_fatal = false;
    for (const auto& e : active()) {
        const ErrorCodeInfo* info = find_error_code(e.code);
        if (info == nullptr) continue;
        auto& word = info->fatal ? fatal : non_fatal;
        if (info->bit >= 0) word = static_cast<std::uint16_t>(word | (1U << info->bit));
        (info->fatal ? any_fatal : any_non_fatal) = true;
    }
    state_.fatal_word = fatal;
    state_.non_fatal_word = non_fatal;
    state_.flags =
        static_cast<std::uint16_t>((any_fatal ? 0x0080 : 0) | (any_non_fatal ? 0x0040 : 0));
}

}  // namespace fins::plc
