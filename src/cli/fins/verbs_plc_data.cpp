// `fins` verbs for 02 xx parameter areas, 03 xx program area, 02 40 loop control.
// (Scaffolding: filled in by the issue-3 owner of this group.)
#include "cli/fins/commands.hpp"

namespace fins::cli {

void add_plc_data_verbs(CLI::App&, const GlobalOptions&, int&) {}

}  // namespace fins::cli
