// `fins` verbs for 04 xx mode, 05 xx configuration, 06 20 cycle time, 07 xx clock.
// (Scaffolding: filled in by the issue-3 owner of this group.)
#include "cli/fins/commands.hpp"

namespace fins::cli {

void add_control_verbs(CLI::App&, const GlobalOptions&, int&) {}

}  // namespace fins::cli
