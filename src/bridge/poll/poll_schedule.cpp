#include "bridge/poll/poll_schedule.hpp"

#include <algorithm>
#include <cmath>

namespace fins::bridge {

double spread_phase(std::size_t index) noexcept {
    return std::fmod(static_cast<double>(index) * 0.6180339887498949, 1.0);
}

std::chrono::milliseconds Backoff::cap(unsigned attempt) const noexcept {
    const double c =
        std::min<double>(static_cast<double>(max_.count()),
                         static_cast<double>(min_.count()) * std::pow(2.0, std::min(attempt, 30u)));
    return std::chrono::milliseconds(static_cast<std::int64_t>(c));
}

std::chrono::milliseconds Backoff::next() {
    const auto c = cap(attempt_);
    ++attempt_;
    std::uniform_real_distribution<double> jitter(0.0, static_cast<double>(c.count()));
    return std::chrono::milliseconds(static_cast<std::int64_t>(jitter(random_)));
}

}  // namespace fins::bridge
