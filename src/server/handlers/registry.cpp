// The dispatch table: the group tables joined and sorted once. A command's name and
// execution conditions come from fins::find_command (the codec's W342 5-1-1/5-1-2
// table); this table only says which function runs it.
#include <algorithm>
#include <vector>

#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

namespace {

std::vector<HandlerEntry> build() {
    std::vector<HandlerEntry> all;
    for (auto group : {memory_area_handlers(), parameter_area_handlers(), program_area_handlers(),
                       operating_mode_handlers(), configuration_handlers(), status_handlers(),
                       cpu_status_handlers(), clock_handlers(), message_handlers(),
                       access_right_handlers(), error_log_handlers(), forced_handlers(),
                       file_memory_handlers(), serial_gateway_handlers()})
        all.insert(all.end(), group.begin(), group.end());
    std::sort(all.begin(), all.end(), [](const HandlerEntry& a, const HandlerEntry& b) {
        return a.code.value() < b.code.value();
    });
    return all;
}

// Built at load time (the group tables are constant-initialized), so the request path
// never allocates.
const std::vector<HandlerEntry> all_handlers = build();

const std::vector<HandlerEntry>& table() {
    return all_handlers;
}

}  // namespace

std::span<const HandlerEntry> handler_table() noexcept {
    return table();
}

const HandlerEntry* find_handler(CommandCode code) noexcept {
    const auto& all = table();
    auto it =
        std::lower_bound(all.begin(), all.end(), code.value(),
                         [](const HandlerEntry& e, std::uint16_t v) { return e.code.value() < v; });
    return it != all.end() && it->code == code ? &*it : nullptr;
}

EndCode to_end_code(const std::error_code& error) noexcept {
    if (error.category() == end_code_category())
        return static_cast<EndCode>(static_cast<std::uint16_t>(error.value()));
    return EndCode::command_format_error;
}

}  // namespace fins::server::handlers
