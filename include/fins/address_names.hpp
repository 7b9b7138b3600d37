// The area names parse_address() (fins/address.hpp) knows, for messages and help:
// "CIO IR DR TK W H A T C D E (also TIM CNT DM HR WR AR)". The second list holds the
// names CX-Programmer and the older manuals use, aliases of D H W A T C (W342 5-2-2).
#pragma once

#include <string>

namespace fins {

std::string area_names();

}  // namespace fins
