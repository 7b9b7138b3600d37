// 21 xx handlers. (Scaffolding: filled in by the issue-3 owner of this group.)
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

std::span<const HandlerEntry> error_log_handlers() noexcept {
    return {};
}

}  // namespace fins::server::handlers
