// (Scaffolding: implemented by the issue-3 owner of errors/messages.)
#include "cli/finsd/ctl.hpp"

namespace fins::cli {

int run_ctl(int, char**) {
    return 2;
}

}  // namespace fins::cli
