// 21 01 ERROR CLEAR, 21 02 ERROR LOG READ, 21 03 ERROR LOG CLEAR, 21 40 FINS WRITE
// ACCESS LOG READ, 21 41 FINS WRITE ACCESS LOG CLEAR (W342 5-3-27 .. 5-3-31).
//
// ERROR CLEAR (5-3-27):
// - FFFF clears every error, PROGRAM mode only ("This code can be used in PROGRAM mode
//   only"); in MONITOR / RUN it answers the 22xx code naming the current mode (2205 /
//   2206), as the execution conditions do.
// - FFFE clears the most serious present error; normal when none is present; the same
//   mode refusal when that error is one of the PROGRAM-mode-only codes (5-3-27 comment).
// - Any other code of the 5-3-27 lists: PROGRAM-mode-only codes answer 2205/2206 in
//   MONITOR/RUN whether present or not; otherwise the error is cleared, and an error
//   that is not present is a normal completion. A code outside the lists answers 110C.
// Log reads (5-3-28, 5-3-30): beginning record beyond the number stored -> 1103, with
// nothing but the end code. Fewer records than asked for: the stored ones; ERROR LOG
// READ then answers 1104 with the data, WRITE ACCESS LOG READ a normal completion.
// A beginning record equal to the number stored is not "beyond" it: zero records.
#include "fins/commands/error_log.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

namespace {

// Writes the read header and the records [first, first + n) given by `at(i)`.
template <class At>
void write_records(ByteWriter& out, std::size_t stored, std::size_t first, std::size_t n,
                   At at) noexcept {
    out.u16(log_max_records);
    out.u16(static_cast<std::uint16_t>(stored));
    out.u16(static_cast<std::uint16_t>(n));
    for (std::size_t i = 0; i < n; ++i)
        at(first + i).encode(out);
}

}  // namespace

EndCode execute(HandlerContext& context, const ErrorClear& command, ByteWriter&) {
    auto& plc = context.plc;
    auto& errors = plc.errors();
    const auto now = context.request.now;
    const EndCode mode_refusal = program_mode_only(plc.mode());
    if (command.error_code == clear_all_errors) {
        if (mode_refusal != EndCode::normal_completion) return mode_refusal;
        errors.clear_all(now);
        return EndCode::normal_completion;
    }
    std::uint16_t code = command.error_code;
    if (code == clear_current_error) {
        const plc::ActiveError* worst = errors.most_serious();
        if (worst == nullptr) return EndCode::normal_completion;
        code = worst->code;
    }
    const plc::ErrorCodeInfo* info = plc::find_error_code(code);
    if (info == nullptr) return EndCode::parameter_error;
    if (info->program_mode_only && mode_refusal != EndCode::normal_completion) return mode_refusal;
    errors.clear(code, now);
    return EndCode::normal_completion;
}

EndCode execute(HandlerContext& context, const ErrorLogRead& command, ByteWriter& out) noexcept {
    const auto& errors = context.plc.errors();
    const std::size_t stored = errors.log_size();
    if (command.first > stored) return EndCode::address_range_error;
    const std::size_t n = std::min<std::size_t>(command.count, stored - command.first);
    write_records(out, stored, command.first, n, [&errors](std::size_t i) -> const ErrorLogRecord& {
        return errors.log_record(i);
    });
    if (n < command.count) {
        context.keep_data = true;
        return EndCode::address_range_exceeded;
    }
    return EndCode::normal_completion;
}

EndCode execute(HandlerContext& context, const ErrorLogClear&, ByteWriter&) noexcept {
    context.plc.errors().clear_log();
    return EndCode::normal_completion;
}

EndCode execute(HandlerContext& context, const WriteAccessLogRead& command,
                ByteWriter& out) noexcept {
    const auto& log = context.plc.write_access_log();
    const std::size_t stored = log.size();
    if (command.first > stored) return EndCode::address_range_error;
    const std::size_t n = std::min<std::size_t>(command.count, stored - command.first);
    write_records(out, stored, command.first, n,
                  [&log](std::size_t i) -> const WriteAccessRecord& { return log.at(i); });
    return EndCode::normal_completion;
}

EndCode execute(HandlerContext& context, const WriteAccessLogClear&, ByteWriter&) noexcept {
    context.plc.write_access_log().clear();
    return EndCode::normal_completion;
}

namespace {

constexpr HandlerEntry error_log_table[] = {
    entry<ErrorClear>(),         entry<ErrorLogRead>(),        entry<ErrorLogClear>(),
    entry<WriteAccessLogRead>(), entry<WriteAccessLogClear>(),
};

}  // namespace

std::span<const HandlerEntry> error_log_handlers() noexcept {
    return error_log_table;
}

}  // namespace fins::server::handlers
