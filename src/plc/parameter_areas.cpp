#include "plc/parameter_areas.hpp"

namespace fins::plc {

ParameterAreas::ParameterAreas(const Profile&, Storage&) {}

}  // namespace fins::plc
