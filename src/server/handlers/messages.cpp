// 09 20 MESSAGE READ / MESSAGE CLEAR / FAL/FALS READ (W342 5-3-21 .. 5-3-23, frames
// 6/0920). The parameter word selects the variant (codec: MessageCommand; 110C for a
// word that names none).
//
// - READ: the answer echoes the requested bits, then 32 bytes per requested message in
//   ascending order; an unregistered message reads as 32 spaces (5-3-21). No bits: the
//   word 0000 alone.
// - READ and FAL/FALS READ are reads (5-3-21, 5-3-23: OK under network write protection
//   and while another device holds the access right); they are not logged as writes.
// - CLEAR: a write. The command table accepts 09 20 under every condition so that the
//   reads pass; this handler refuses the clear variant itself, in the order of the
//   execution conditions: network write protection 2102 (5-1-2 "Disabled"), then the
//   access right held by another device 3001 (5-1-2 "Disabled (MESSAGE CLEAR only)",
//   5-3-22). Like any write refused by its execution conditions it is then not logged;
//   once past them it goes into the FINS write access log whatever its end code.
//   Clearing an unregistered message is a normal completion.
// - FAL/FALS READ: number 1-511 (FAL(006)/FALS(007) range); 0 or above 511 answers
//   110C. The message of FALS n (else FAL n) while that error is present, 16 spaces
//   otherwise (5-3-23 "no message has been registered").
#include "fins/commands/diagnostics.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

namespace {

EndCode read_messages(HandlerContext& context, const MessageRead& command, ByteWriter& out) {
    const auto& messages = context.plc.messages();
    out.u16(command.messages);
    for (std::size_t n = 0; n < msg_count; ++n)
        if ((command.messages >> n) & 1U) out.text(messages.text(n), msg_text_size);
    return EndCode::normal_completion;
}

EndCode clear_messages(HandlerContext& context, const MessageClear& command) {
    const auto& source = context.header.source;
    // W342 5-1-2 note 5: only requests "via networks" (not in-process ones).
    if (via_network(context.request.link) && context.plc.network_write_protected_from(source))
        return EndCode::write_protected;
    if (context.plc.access_right_held_by_other(source)) return EndCode::no_access_right;
    context.write = true;
    context.plc.messages().clear(command.messages);
    return EndCode::normal_completion;
}

EndCode read_fal(HandlerContext& context, const FalFalsRead& command, ByteWriter& out) {
    if (command.number == 0 || command.number > max_fal_number) return EndCode::parameter_error;
    const auto message = context.plc.errors().fal_message(command.number);
    // The answer echoes the command word, bit 15 included (frames 6/0920 "same layout").
    out.u16(static_cast<std::uint16_t>(fal_read_bit | command.number));
    out.text(message.value_or(std::string_view{}), error_message_size);
    return EndCode::normal_completion;
}

}  // namespace

EndCode execute(HandlerContext& context, const MessageCommand& command, ByteWriter& out) {
    if (const auto* read = std::get_if<MessageRead>(&command.command))
        return read_messages(context, *read, out);
    if (const auto* clear = std::get_if<MessageClear>(&command.command))
        return clear_messages(context, *clear);
    return read_fal(context, std::get<FalFalsRead>(command.command), out);
}

namespace {

constexpr HandlerEntry message_table[] = {entry<MessageCommand>()};

}  // namespace

std::span<const HandlerEntry> message_handlers() noexcept {
    return message_table;
}

}  // namespace fins::server::handlers
