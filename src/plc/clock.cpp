// The CPU Unit clock (see clock.hpp for the model).
#include "plc/clock.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <limits>

namespace fins::plc {

namespace {

constexpr std::int64_t seconds_per_day = 86400;
constexpr std::int64_t days_per_week = 7;
// A restored offset is trusted only within +-200 years, so a damaged state file can
// never push the arithmetic out of range.
constexpr std::int64_t max_offset = 200LL * 366 * seconds_per_day;

constexpr std::int64_t floor_div(std::int64_t a, std::int64_t b) noexcept {
    return a / b - ((a % b != 0 && (a < 0) != (b < 0)) ? 1 : 0);
}
constexpr std::int64_t floor_mod(std::int64_t a, std::int64_t b) noexcept {
    return a - floor_div(a, b) * b;
}

}  // namespace

Clock::Clock(const Profile&, Storage& storage)
    : state_(storage.object<State>("clock", Retention::retained)) {}

CivilSeconds Clock::to_civil(int year, unsigned month, unsigned day, unsigned hour, unsigned minute,
                             unsigned second) noexcept {
    using namespace std::chrono;
    const sys_days date{std::chrono::year{year} / std::chrono::month{month} /
                        std::chrono::day{day}};
    return static_cast<CivilSeconds>(date.time_since_epoch().count()) * seconds_per_day +
           std::int64_t{hour} * 3600 + std::int64_t{minute} * 60 + std::int64_t{second};
}

unsigned Clock::days_in_month(int year, unsigned month) noexcept {
    using namespace std::chrono;
    if (month < 1 || month > 12) return 0;
    const year_month_day_last last{std::chrono::year{year},
                                   month_day_last{std::chrono::month{month}}};
    return static_cast<unsigned>(last.day());
}

unsigned Clock::weekday(CivilSeconds t) noexcept {
    // 1970-01-01 was a Thursday (4).
    return static_cast<unsigned>(floor_mod(floor_div(t, seconds_per_day) + 4, days_per_week));
}

CivilSeconds Clock::host_local(TimePoint now) noexcept {
    const auto seconds = std::chrono::floor<std::chrono::seconds>(now).time_since_epoch().count();
    // The last second converted, per thread: a plant's units read the clock for every
    // write access record and status within the same second, and localtime_r costs far
    // more than the arithmetic around it (it reads the time zone only once anyway).
    thread_local std::int64_t cached_second = std::numeric_limits<std::int64_t>::min();
    thread_local CivilSeconds cached_local = 0;
    if (seconds == cached_second) return cached_local;
    const auto t = static_cast<std::time_t>(seconds);
    std::tm tm{};
    if (::localtime_r(&t, &tm) == nullptr) return seconds;
    cached_second = seconds;
    return cached_local =
               to_civil(tm.tm_year + 1900, static_cast<unsigned>(tm.tm_mon + 1),
                        static_cast<unsigned>(tm.tm_mday), static_cast<unsigned>(tm.tm_hour),
                        static_cast<unsigned>(tm.tm_min),
                        static_cast<unsigned>(std::min(tm.tm_sec, 59)));  // leap second -> :59
}

CivilSeconds Clock::civil(TimePoint now) const noexcept {
    return host_local(now) + std::clamp(state_.offset_seconds, -max_offset, max_offset);
}

ClockTime Clock::read(TimePoint now) const noexcept {
    using namespace std::chrono;
    const CivilSeconds t = civil(now);
    // The same second as the last read, with the same weekday shift: the same reading
    // (a plant's scenarios stamp a write access record every tick).
    if (t == cached_.civil && state_.weekday_shift == cached_.weekday_shift) return cached_.time;
    const auto days = floor_div(t, seconds_per_day);
    const auto second_of_day = t - days * seconds_per_day;
    const year_month_day date{sys_days{std::chrono::days{days}}};
    ClockTime out;
    out.year = static_cast<std::uint8_t>(floor_mod(int{date.year()}, 100));
    out.month = static_cast<std::uint8_t>(unsigned{date.month()});
    out.day = static_cast<std::uint8_t>(unsigned{date.day()});
    out.hour = static_cast<std::uint8_t>(second_of_day / 3600);
    out.minute = static_cast<std::uint8_t>(second_of_day / 60 % 60);
    out.second = static_cast<std::uint8_t>(second_of_day % 60);
    out.day_of_week = static_cast<std::uint8_t>(floor_mod(
        std::int64_t{weekday(t)} + floor_mod(state_.weekday_shift, days_per_week), days_per_week));
    cached_ = {t, state_.weekday_shift, out};
    return out;
}

EndCode Clock::write(const ClockWrite& s, TimePoint now) noexcept {
    const int year = full_year(s.year);
    const unsigned second = s.second.value_or(0);
    const bool valid = s.year <= 99 && s.month >= 1 && s.month <= 12 && s.day >= 1 &&
                       s.day <= days_in_month(year, s.month) && s.hour <= 23 && s.minute <= 59 &&
                       second <= 59 && (!s.day_of_week || *s.day_of_week <= 6);
    if (!valid) return EndCode::parameter_error;

    const auto kept_day_of_week = read(now).day_of_week;
    const CivilSeconds target = to_civil(year, s.month, s.day, s.hour, s.minute, second);
    const unsigned day_of_week = s.day_of_week.value_or(kept_day_of_week);
    state_.offset_seconds = target - host_local(now);
    ++version_;
    state_.weekday_shift =
        floor_mod(std::int64_t{day_of_week} - std::int64_t{weekday(target)}, days_per_week);
    return EndCode::normal_completion;
}

}  // namespace fins::plc
