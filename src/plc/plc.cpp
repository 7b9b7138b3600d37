#include "plc/plc.hpp"

#include <utility>

namespace fins::plc {

Plc::Plc(Profile profile) : memory_(std::move(profile)) {}

}  // namespace fins::plc
