// MSG messages 0-7 for MESSAGE READ / MESSAGE CLEAR (W342 5-3-21, 5-3-22) and the
// "message yes/no" word of CPU UNIT STATUS READ (5-3-17).
//
// A message is registered when MSG(046) ran with it (here: set() from the control
// channel or the configuration) and stays until MESSAGE CLEAR. Up to 32 ASCII bytes;
// a reader pads it with spaces. Messages live in cleared storage: gone after a restart.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

class Messages {
  public:
    static constexpr std::size_t count = 8;      // MSG 0-7
    static constexpr std::size_t max_size = 32;  // bytes per message

    Messages(const Profile& profile, Storage& storage);

    // Registers message `number`. False (nothing changes) for number > 7 or a text over
    // 32 bytes. An empty text registers an all-space message.
    bool set(std::size_t number, std::string_view text) noexcept;
    // Unregisters every message whose bit is set in `mask` (bit k = MSG k).
    void clear(std::uint8_t mask) noexcept;

    [[nodiscard]] bool registered(std::size_t number) const noexcept;
    // The text as set (not padded); empty when not registered.
    [[nodiscard]] std::string_view text(std::size_t number) const noexcept;
    // 06 01 "message yes/no": bit k on while MSG k is registered.
    [[nodiscard]] std::uint8_t present() const noexcept { return state_.present; }

    struct State {
        std::array<std::array<char, max_size>, count> texts{};
        std::array<std::uint8_t, count> sizes{};
        std::uint8_t present = 0;
    };

  private:
    State& state_;
};

}  // namespace fins::plc
