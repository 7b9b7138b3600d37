// 22 0A MEMORY AREA FILE TRANSFER, 22 0B PARAMETER AREA FILE TRANSFER and 22 0C PROGRAM
// AREA FILE TRANSFER (W342 5-3-39 .. 5-3-41): the transfers between files and the PLC's
// areas, with the 5-1-2 notes the dispatcher's table cannot express (only area -> file in
// RUN/MONITOR or under DIP switch write protection). The codec's half is
// src/codec/commands/file_transfer.cpp; the table entries are file_memory.cpp's.
//
// Data files: a 48-byte header of zeros (CJ2SW p.269/272 give the size, not the
// content), then the data: words high byte first (.IOM, .STD), program bytes (.OBJ).
// Compare answers 0000 with the count when everything matched, else 2007 with the
// number of items that matched before the first difference (22 0B: its position).
#include <algorithm>
#include <vector>

#include "fins/commands/file_memory.hpp"
#include "fins/commands/parameter_area.hpp"
#include "fins/commands/program_area.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

EndCode execute(HandlerContext& context, const MemoryAreaFileTransfer& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const ParameterAreaFileTransfer& command, ByteWriter& out);
EndCode execute(HandlerContext& context, const ProgramAreaFileTransfer& command, ByteWriter& out);

namespace {

// A new file is dated with the CPU Unit's clock.
plc::CivilSeconds now(const HandlerContext& context) {
    return context.plc.clock().civil(context.request.now);
}

EndCode code_of(const std::error_code& e) noexcept {
    return to_end_code(e);
}

// 5-3-39 table: the word areas a memory area-file transfer may name.
bool transfer_area(std::uint8_t code) noexcept {
    return (code >= 0xB0 && code <= 0xB3) || code == 0x89 || code == 0x82 ||
           (code >= 0xA0 && code <= 0xAF) || (code >= 0x50 && code <= 0x5F) ||
           (code >= 0x60 && code <= 0x68) || code == 0x98;
}

std::vector<std::uint8_t> with_header(Bytes data) {
    // Sized once (a header-sized vector grown by insert() also trips GCC 12's
    // -Warray-bounds in Release builds).
    std::vector<std::uint8_t> out(plc::data_file_header_size + data.size(), 0);
    std::copy(data.begin(), data.end(),
              out.begin() + static_cast<std::ptrdiff_t>(plc::data_file_header_size));
    return out;
}

// The data after the header (empty when the file is shorter than the header).
Bytes body(const std::vector<std::uint8_t>& file) noexcept {
    if (file.size() < plc::data_file_header_size) return {};
    return Bytes(file).subspan(plc::data_file_header_size);
}

std::size_t matching_prefix(Bytes a, Bytes b) noexcept {
    const auto n = std::min(a.size(), b.size());
    return static_cast<std::size_t>(
        std::mismatch(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(n), b.begin()).first -
        a.begin());
}

}  // namespace

// 5-3-39. File -> memory loads at most `count` words (fewer when the file is shorter)
// and answers how many; memory -> file never overwrites (2107).
EndCode execute(HandlerContext& context, const MemoryAreaFileTransfer& command, ByteWriter& out) {
    if (command.mode > static_cast<std::uint16_t>(FileTransferMode::compare))
        return EndCode::parameter_error;
    if (!transfer_area(command.start.area_code)) return EndCode::area_classification_missing;
    auto& plc = context.plc;
    auto& memory = plc.memory();
    const auto mode = static_cast<FileTransferMode>(command.mode);
    const auto intent =
        mode == FileTransferMode::from_file ? plc::Intent::write : plc::Intent::read;
    const auto range = memory.locate(command.start, command.count, use_word_ops, intent);
    if (!range) return code_of(range.error());
    if (range->kind != ElementKind::word) return EndCode::area_classification_missing;

    if (mode == FileTransferMode::to_file) {
        std::vector<std::uint8_t> data(range->byte_size());
        ByteWriter w(data);
        memory.read(*range, w, context.request.now);
        const auto file = with_header(data);
        if (const auto code = plc.files().create(command.disk, command.file, command.directory,
                                                 file, now(context));
            code != EndCode::normal_completion)
            return code;
        out.u16(command.count);
        return EndCode::normal_completion;
    }
    const auto file = plc.files().load(command.disk, command.file, command.directory);
    if (!file) return code_of(file.error());
    const Bytes stored = body(*file);
    if (mode == FileTransferMode::from_file) {
        const auto words = std::min<std::size_t>(command.count, stored.size() / 2);
        const auto part =
            memory.locate(command.start, static_cast<std::uint32_t>(words), use_word_ops, intent);
        if (!part) return code_of(part.error());
        if (const auto code = memory.write(*part, stored.first(words * 2));
            code != EndCode::normal_completion)
            return code;
        out.u16(static_cast<std::uint16_t>(words));
        return EndCode::normal_completion;
    }
    std::vector<std::uint8_t> data(range->byte_size());
    ByteWriter w(data);
    memory.read(*range, w, context.request.now);
    const auto same = matching_prefix(data, stored) / 2;
    out.u16(static_cast<std::uint16_t>(same));
    if (same == command.count) return EndCode::normal_completion;
    context.keep_data = true;
    return EndCode::data_mismatch;
}

// 5-3-40. The whole area (start 0000, count FFFF); file -> area only in PROGRAM mode
// and not under DIP switch write protection (5-1-2 notes 1-2).
EndCode execute(HandlerContext& context, const ParameterAreaFileTransfer& command,
                ByteWriter& out) {
    if (command.mode > static_cast<std::uint16_t>(FileTransferMode::compare))
        return EndCode::parameter_error;
    const auto* info = find_parameter_area(command.area);
    if (info == nullptr || command.area == parameter_area_all)
        return EndCode::area_classification_missing;
    if (command.start != 0) return EndCode::address_range_error;
    if (command.count != whole_parameter_area) return EndCode::parameter_error;
    auto& plc = context.plc;
    auto words = plc.parameters().words(command.area);
    const auto mode = static_cast<FileTransferMode>(command.mode);
    std::vector<std::uint8_t> data(words.size() * 2);
    for (std::size_t i = 0; i < words.size(); ++i) {
        data[2 * i] = static_cast<std::uint8_t>(words[i] >> 8);
        data[2 * i + 1] = static_cast<std::uint8_t>(words[i]);
    }
    if (mode == FileTransferMode::to_file) {
        if (const auto code = plc.files().create(command.disk, command.file, command.directory,
                                                 with_header(data), now(context));
            code != EndCode::normal_completion)
            return code;
        out.u16(static_cast<std::uint16_t>(words.size()));
        return EndCode::normal_completion;
    }
    if (mode == FileTransferMode::from_file) {
        if (const auto code = program_mode_only(plc.mode()); code != EndCode::normal_completion)
            return code;
        if (plc.dip_write_protection()) return EndCode::read_only;
    }
    const auto file = plc.files().load(command.disk, command.file, command.directory);
    if (!file) return code_of(file.error());
    const Bytes stored = body(*file);
    if (mode == FileTransferMode::from_file) {
        if (stored.size() != data.size()) return EndCode::data_mismatch;
        for (std::size_t i = 0; i < words.size(); ++i)
            words[i] = static_cast<std::uint16_t>((stored[2 * i] << 8) | stored[2 * i + 1]);
        out.u16(static_cast<std::uint16_t>(words.size()));
        return EndCode::normal_completion;
    }
    const auto same = matching_prefix(data, stored) / 2;
    out.u16(static_cast<std::uint16_t>(same));
    if (same == words.size() && stored.size() == data.size()) return EndCode::normal_completion;
    context.keep_data = true;
    return EndCode::data_mismatch;
}

// 5-3-41. The program is saved up to its last non-zero 4-byte unit ("steps used x 4",
// CJ2SW p.272); loading clears the rest of the UM.
EndCode execute(HandlerContext& context, const ProgramAreaFileTransfer& command, ByteWriter& out) {
    if (command.mode > static_cast<std::uint16_t>(FileTransferMode::compare))
        return EndCode::parameter_error;
    if (command.program_number != program_number_all) return EndCode::program_missing;
    if (command.start != 0) return EndCode::address_range_error;
    if (command.length != 0xFFFFFFFF) return EndCode::parameter_error;
    auto& plc = context.plc;
    auto& program = plc.program();
    const auto mode = static_cast<FileTransferMode>(command.mode);
    const auto um = program.bytes();
    std::size_t used = um.size();
    while (used > 0 && um[used - 1] == 0)
        --used;
    used = (used + program_alignment - 1) / program_alignment * program_alignment;
    used = std::min(used, um.size());
    if (mode == FileTransferMode::to_file) {
        // 5-3-41: "prohibit save to protected memory card and program transfer".
        if (program.prohibit_transfer()) return EndCode::read_protected;
        if (const auto code = plc.files().create(command.disk, command.file, command.directory,
                                                 with_header(um.first(used)), now(context));
            code != EndCode::normal_completion)
            return code;
        out.u32(static_cast<std::uint32_t>(used));
        return EndCode::normal_completion;
    }
    if (mode == FileTransferMode::from_file) {
        if (const auto code = program_mode_only(plc.mode()); code != EndCode::normal_completion)
            return code;
        if (plc.dip_write_protection()) return EndCode::read_only;
        if (program.prohibit_overwrite()) return EndCode::write_protected;
    }
    const auto file = plc.files().load(command.disk, command.file, command.directory);
    if (!file) return code_of(file.error());
    const Bytes stored = body(*file);
    if (mode == FileTransferMode::from_file) {
        if (stored.size() > um.size()) return EndCode::address_range_exceeded;
        std::fill(um.begin(), um.end(), std::uint8_t{0});
        std::copy(stored.begin(), stored.end(), um.begin());
        out.u32(static_cast<std::uint32_t>(stored.size()));
        return EndCode::normal_completion;
    }
    const auto same = matching_prefix(um.first(used), stored);
    out.u32(static_cast<std::uint32_t>(same));
    if (same == used && stored.size() == used) return EndCode::normal_completion;
    context.keep_data = true;
    return EndCode::data_mismatch;
}

}  // namespace fins::server::handlers
