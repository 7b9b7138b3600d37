#include "plc/messages.hpp"

#include <algorithm>

namespace fins::plc {

Messages::Messages(const Profile&, Storage& storage)
    : state_(storage.object<State>("messages", Retention::cleared)) {}

bool Messages::set(std::size_t number, std::string_view text) noexcept {
    if (number >= count || text.size() > max_size) return false;
    auto& slot = state_.texts[number];
    std::fill(slot.begin(), slot.end(), ' ');
    std::copy(text.begin(), text.end(), slot.begin());
    state_.sizes[number] = static_cast<std::uint8_t>(text.size());
    state_.present = static_cast<std::uint8_t>(state_.present | (1U << number));
    return true;
}

void Messages::clear(std::uint8_t mask) noexcept {
    for (std::size_t n = 0; n < count; ++n)
        if ((static_cast<unsigned>(mask) >> n) & 1U) state_.sizes[n] = 0;
    state_.present = static_cast<std::uint8_t>(state_.present & ~mask);
}

bool Messages::registered(std::size_t number) const noexcept {
    return number < count && ((static_cast<unsigned>(state_.present) >> number) & 1U) != 0;
}

std::string_view Messages::text(std::size_t number) const noexcept {
    if (!registered(number)) return {};
    const std::size_t size = std::min<std::size_t>(state_.sizes[number], max_size);
    return {state_.texts[number].data(), size};
}

}  // namespace fins::plc
