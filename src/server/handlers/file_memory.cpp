// 22 xx file memory: W342 5-3-32 .. 5-3-38 and 5-3-42, the commands on files and
// directories; the file devices and their end codes live in plc::FileMemory. The
// transfers between files and the PLC's areas (22 0A .. 22 0C) are file_transfer.cpp's,
// as in the codec; 22 20 is memory_cassette.cpp's. This file holds the table of all 22 xx
// handlers. Execution conditions, the write access log and network write protection are
// the dispatcher's (fins::command_table rows 22 xx).
#include "fins/commands/file_memory.hpp"
#include "fins/commands/memory_cassette.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

EndCode execute(HandlerContext& context, const FileNameRead& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const SingleFileRead& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const SingleFileWrite& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const FileMemoryFormat& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const FileDelete& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const FileCopy& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const FileNameChange& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const DirectoryCreateDelete& command, ByteWriter& out);
// 22 0A .. 22 0C: file_transfer.cpp.
EndCode execute(HandlerContext& context, const MemoryAreaFileTransfer& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const ParameterAreaFileTransfer& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const ProgramAreaFileTransfer& command, ByteWriter& out);
// 22 20: memory_cassette.cpp.
EndCode execute(HandlerContext& context, const MemoryCassetteTransfer& command, ByteWriter& out);

namespace {

plc::CivilSeconds now(const HandlerContext& context) {
    return context.plc.clock().civil(context.request.now);
}

EndCode code_of(const std::error_code& e) noexcept {
    return to_end_code(e);
}

}  // namespace

// 5-3-32.
EndCode execute(HandlerContext& context, const FileNameRead& command, ByteWriter& out) {
    const auto r = context.plc.files().list(command);
    if (!r) return code_of(r.error());
    r->encode(out);
    return EndCode::normal_completion;
}

// 5-3-33. Position 0 and length 0: an existence check (5-3-33 comment).
EndCode execute(HandlerContext& context, const SingleFileRead& command, ByteWriter& out) {
    const auto r = context.plc.files().read(command);
    if (!r) return code_of(r.error());
    r->encode(out);
    return EndCode::normal_completion;
}

// 5-3-34: dated with the CPU Unit's clock.
EndCode execute(HandlerContext& context, const SingleFileWrite& command, ByteWriter&) {
    return context.plc.files().write(command, now(context));
}

// 5-3-35.
EndCode execute(HandlerContext& context, const FileMemoryFormat& command, ByteWriter&) {
    return context.plc.files().format(command.disk, context.plc.memory().current_em_bank(),
                                      now(context));
}

// 5-3-36.
EndCode execute(HandlerContext& context, const FileDelete& command, ByteWriter& out) {
    const auto r = context.plc.files().remove(command);
    if (!r) return code_of(r.error());
    FileDeleteResponse{*r}.encode(out);
    return EndCode::normal_completion;
}

// 5-3-37.
EndCode execute(HandlerContext& context, const FileCopy& command, ByteWriter&) {
    return context.plc.files().copy(command);
}

// 5-3-38.
EndCode execute(HandlerContext& context, const FileNameChange& command, ByteWriter&) {
    return context.plc.files().rename(command);
}

// 5-3-42: a new directory is dated with the CPU Unit's clock.
EndCode execute(HandlerContext& context, const DirectoryCreateDelete& command, ByteWriter&) {
    return context.plc.files().directory(command, now(context));
}

namespace {

constexpr HandlerEntry file_memory_table[] = {
    entry<FileNameRead>(),
    entry<SingleFileRead>(),
    entry<SingleFileWrite>(),
    entry<FileMemoryFormat>(),
    entry<FileDelete>(),
    entry<FileCopy>(),
    entry<FileNameChange>(),
    entry<MemoryAreaFileTransfer>(),
    entry<ParameterAreaFileTransfer>(),
    entry<ProgramAreaFileTransfer>(),
    entry<DirectoryCreateDelete>(),
    entry<MemoryCassetteTransfer>(),
};

}  // namespace

std::span<const HandlerEntry> file_memory_handlers() noexcept {
    return file_memory_table;
}

}  // namespace fins::server::handlers
