#include "plc/profile.hpp"

namespace fins::plc {

namespace {

// W342 5-2-2 note 2: 50-5F are the CJ2-only alternative codes for EM bank 0-F words.
constexpr bool is_cj2_em_code(std::uint8_t code) noexcept {
    return code >= 0x50 && code <= 0x5F;
}

}  // namespace

bool Profile::accepts(const MemoryAreaSegment& segment) const noexcept {
    if (segment.cv_mode && !cv_mode_codes) return false;
    if (is_cj2_em_code(segment.code) && !cj2_em_codes) return false;
    if (segment.region == Region::em && segment.em_bank >= em_banks) return false;
    if ((segment.region == Region::em_current || segment.region == Region::em_bank_number) &&
        em_banks == 0)
        return false;
    return true;
}

bool Profile::supports(CommandCode code) const noexcept {
    if (commands.empty()) return true;
    for (auto c : commands)
        if (c == code.value()) return true;
    return false;
}

Profile cj2h() {
    return Profile{};
}

}  // namespace fins::plc
