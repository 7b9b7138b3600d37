// `fins` verbs for 06 01 status, 09 20 messages, 0C xx access right, 21 xx error log and access
// log, 23 xx forcing. (Scaffolding: filled in by the issue-3 owner of this group.)
#include "cli/fins/commands.hpp"

namespace fins::cli {

void add_diagnostic_verbs(CLI::App&, const GlobalOptions&, int&) {}

}  // namespace fins::cli
