// The dispatch table: one row per implemented command, built from the command types.
// A command's name and execution conditions come from fins::find_command (the codec's
// W342 5-1-1/5-1-2 table); this table only says which function runs it.
#include <array>

#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

namespace {

// Decodes C's parameters (1001/1002/... from the codec) and runs its handler.
template <class C>
EndCode handle(HandlerContext& context, Bytes parameters, ByteWriter& out) {
    const auto command = C::decode(parameters);
    if (!command) return to_end_code(command.error());
    return execute(context, *command, out);
}

template <class C>
constexpr HandlerEntry entry() noexcept {
    return HandlerEntry{C::code, &handle<C>};
}

constexpr std::array handlers{
    entry<MemoryAreaRead>(),         entry<MemoryAreaWrite>(),    entry<MemoryAreaFill>(),
    entry<MultipleMemoryAreaRead>(), entry<MemoryAreaTransfer>(),
};

}  // namespace

std::span<const HandlerEntry> handler_table() noexcept {
    return handlers;
}

const HandlerEntry* find_handler(CommandCode code) noexcept {
    for (const auto& h : handlers)
        if (h.code == code) return &h;
    return nullptr;
}

EndCode to_end_code(const std::error_code& error) noexcept {
    if (error.category() == end_code_category())
        return static_cast<EndCode>(static_cast<std::uint16_t>(error.value()));
    return EndCode::command_format_error;
}

}  // namespace fins::server::handlers
