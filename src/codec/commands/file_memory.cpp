// File memory commands 22 01 .. 22 08 and 22 15 (W342 5-3-32 .. 5-3-38, 5-3-42, fins-frames
// 6 "22 xx"); the transfers 22 0A .. 22 0C are file_transfer.cpp's.
//
// Server side (decode): 1002 when the parameters end before a fixed field or before the
// bytes a length field announces, 1001 when bytes are left over. Names and paths are
// copied as they are; plc::FileMemory judges them.
// Client side (decode_response): any length or echo mismatch is malformed_response.
#include "fins/commands/file_memory.hpp"
#include "codec/command_codec.hpp"
#include "codec/commands/file_fields.hpp"

namespace fins {

using codec::empty_response;
using codec::end_code;
using codec::malformed;
using namespace codec::file_fields;

constexpr std::uint8_t pad = 0x20;  // a file name's unused characters

std::optional<FileName> FileName::from(std::string_view text) noexcept {
    FileName n;
    n.bytes.fill(pad);
    const auto dot = text.find('.');
    const auto base = text.substr(0, dot);
    const auto ext = dot == std::string_view::npos ? std::string_view{} : text.substr(dot + 1);
    if (base.empty() || base.size() > 8 || ext.size() > 3) return std::nullopt;
    if (ext.find('.') != std::string_view::npos) return std::nullopt;
    for (std::size_t i = 0; i < base.size(); ++i)
        n.bytes[i] = static_cast<std::uint8_t>(base[i]);
    if (!ext.empty()) {
        n.bytes[8] = '.';
        for (std::size_t i = 0; i < ext.size(); ++i)
            n.bytes[9 + i] = static_cast<std::uint8_t>(ext[i]);
    }
    return n;
}

std::string FileName::text() const {
    std::string base(bytes.begin(), bytes.begin() + 8);
    std::string ext(bytes.begin() + 9, bytes.end());
    while (!base.empty() && base.back() == ' ')
        base.pop_back();
    while (!ext.empty() && ext.back() == ' ')
        ext.pop_back();
    if (bytes[8] != '.' || ext.empty()) return base;
    return base + "." + ext;
}

std::uint32_t pack_file_date(int year, unsigned month, unsigned day, unsigned hour, unsigned minute,
                             unsigned second) noexcept {
    const auto y = static_cast<std::uint32_t>(year < 1980 ? 0 : (year > 2107 ? 127 : year - 1980));
    return (y << 25) | ((month & 0x0Fu) << 21) | ((day & 0x1Fu) << 16) | ((hour & 0x1Fu) << 11) |
           ((minute & 0x3Fu) << 5) | ((second / 2) & 0x1Fu);
}

// ---- 22 01 FILE NAME READ (5-3-32) ----

void FileNameReadResponse::encode(ByteWriter& w) const noexcept {
    write_name(w, disk.volume_label);
    w.u32(disk.date);
    w.u32(disk.total_capacity);
    w.u32(disk.free_capacity);
    w.u16(disk.total_files);
    w.u16(static_cast<std::uint16_t>(files.size() | (last ? file_last_bit : 0)));
    for (const auto& f : files) {
        write_name(w, f.name);
        w.u32(f.date);
        w.u32(f.size);
        w.u16(f.attribute);
    }
}

void FileNameRead::encode(ByteWriter& w) const noexcept {
    w.u16(disk);
    w.u16(first);
    w.u16(count);
    write_path(w, directory);
}

Result<FileNameRead> FileNameRead::decode(Bytes parameters) {
    ByteReader r(parameters);
    FileNameRead c;
    c.disk = r.u16();
    c.first = r.u16();
    c.count = r.u16();
    c.directory = read_path(r);
    return checked(std::move(c), r);
}

Result<FileNameRead::Response> FileNameRead::decode_response(Bytes data) const {
    ByteReader r(data);
    Response out;
    out.disk.volume_label = read_name(r);
    out.disk.date = r.u32();
    out.disk.total_capacity = r.u32();
    out.disk.free_capacity = r.u32();
    out.disk.total_files = r.u16();
    const auto raw = r.u16();
    out.last = (raw & file_last_bit) != 0;
    const auto n = static_cast<std::uint16_t>(raw & 0x7FFFu);
    if (r.truncated() || n > count || r.remaining() != std::size_t{n} * file_entry_size)
        return malformed();
    for (std::uint16_t i = 0; i < n; ++i) {
        FileEntry e;
        e.name = read_name(r);
        e.date = r.u32();
        e.size = r.u32();
        e.attribute = r.u16();
        out.files.push_back(e);
    }
    return out;
}

// ---- 22 02 SINGLE FILE READ (5-3-33) ----

void SingleFileReadResponse::encode(ByteWriter& w) const noexcept {
    w.u32(file_size);
    w.u32(position);
    w.u16(static_cast<std::uint16_t>(data.size() | (last ? file_last_bit : 0)));
    w.bytes(data);
}

void SingleFileRead::encode(ByteWriter& w) const noexcept {
    w.u16(disk);
    write_name(w, file);
    w.u32(position);
    w.u16(length);
    write_path(w, directory);
}

Result<SingleFileRead> SingleFileRead::decode(Bytes parameters) {
    ByteReader r(parameters);
    SingleFileRead c;
    c.disk = r.u16();
    c.file = read_name(r);
    c.position = r.u32();
    c.length = r.u16();
    c.directory = read_path(r);
    return checked(std::move(c), r);
}

Result<SingleFileRead::Response> SingleFileRead::decode_response(Bytes data) const {
    ByteReader r(data);
    Response out;
    out.file_size = r.u32();
    out.position = r.u32();
    const auto raw = r.u16();
    out.last = (raw & file_last_bit) != 0;
    const std::size_t n = raw & 0x7FFFu;
    if (r.truncated() || out.position != position || n > length || r.remaining() != n)
        return malformed();
    const auto bytes = r.rest();
    out.data.assign(bytes.begin(), bytes.end());
    return out;
}

// ---- 22 03 SINGLE FILE WRITE (5-3-34) ----

void SingleFileWrite::encode(ByteWriter& w) const noexcept {
    w.u16(disk);
    w.u16(mode);
    write_name(w, file);
    w.u32(position);
    w.u16(static_cast<std::uint16_t>(data.size()));
    w.bytes(data);
    write_path(w, directory);
}

Result<SingleFileWrite> SingleFileWrite::decode(Bytes parameters) {
    ByteReader r(parameters);
    SingleFileWrite c;
    c.disk = r.u16();
    c.mode = r.u16();
    c.file = read_name(r);
    c.position = r.u32();
    const auto length = r.u16();
    c.data = r.bytes(length);
    c.directory = read_path(r);
    return checked(std::move(c), r);
}

Result<SingleFileWrite::Response> SingleFileWrite::decode_response(Bytes response) const {
    return empty_response(response);
}

// ---- 22 04 FILE MEMORY FORMAT (5-3-35) ----

void FileMemoryFormat::encode(ByteWriter& w) const noexcept {
    w.u16(disk);
}

Result<FileMemoryFormat> FileMemoryFormat::decode(Bytes parameters) {
    ByteReader r(parameters);
    FileMemoryFormat c;
    c.disk = r.u16();
    return checked(c, r);
}

Result<FileMemoryFormat::Response> FileMemoryFormat::decode_response(Bytes data) const {
    return empty_response(data);
}

// ---- 22 05 FILE DELETE (5-3-36) ----

void FileDeleteResponse::encode(ByteWriter& w) const noexcept {
    w.u16(deleted);
}

void FileDelete::encode(ByteWriter& w) const noexcept {
    w.u16(disk);
    w.u16(static_cast<std::uint16_t>(files.size()));
    for (const auto& f : files)
        write_name(w, f);
    write_path(w, directory);
}

Result<FileDelete> FileDelete::decode(Bytes parameters) {
    ByteReader r(parameters);
    FileDelete c;
    c.disk = r.u16();
    const auto n = r.u16();
    // A count the frame cannot hold is short input, not a reason to reserve memory.
    if (std::size_t{n} * 12 > r.remaining()) return end_code(EndCode::command_too_short);
    c.files.reserve(n);
    for (std::uint16_t i = 0; i < n; ++i)
        c.files.push_back(read_name(r));
    c.directory = read_path(r);
    return checked(std::move(c), r);
}

Result<FileDelete::Response> FileDelete::decode_response(Bytes data) const {
    ByteReader r(data);
    FileDeleteResponse out{r.u16()};
    if (r.remaining() != 0 || r.truncated() || out.deleted > files.size()) return malformed();
    return out;
}

// ---- 22 07 FILE COPY (5-3-37; directory blocks after both names, frames-serial-files 4.2) ----

void FileCopy::encode(ByteWriter& w) const noexcept {
    w.u16(source_disk);
    write_name(w, source);
    w.u16(destination_disk);
    write_name(w, destination);
    write_path(w, source_directory);
    write_path(w, destination_directory);
}

Result<FileCopy> FileCopy::decode(Bytes parameters) {
    ByteReader r(parameters);
    FileCopy c;
    c.source_disk = r.u16();
    c.source = read_name(r);
    c.destination_disk = r.u16();
    c.destination = read_name(r);
    c.source_directory = read_path(r);
    c.destination_directory = read_path(r);
    return checked(std::move(c), r);
}

Result<FileCopy::Response> FileCopy::decode_response(Bytes data) const {
    return empty_response(data);
}

// ---- 22 08 FILE NAME CHANGE (5-3-38) ----

void FileNameChange::encode(ByteWriter& w) const noexcept {
    w.u16(disk);
    write_name(w, old_name);
    write_name(w, new_name);
    write_path(w, directory);
}

Result<FileNameChange> FileNameChange::decode(Bytes parameters) {
    ByteReader r(parameters);
    FileNameChange c;
    c.disk = r.u16();
    c.old_name = read_name(r);
    c.new_name = read_name(r);
    c.directory = read_path(r);
    return checked(std::move(c), r);
}

Result<FileNameChange::Response> FileNameChange::decode_response(Bytes data) const {
    return empty_response(data);
}

// ---- 22 15 CREATE/DELETE DIRECTORY (5-3-42) ----

void DirectoryCreateDelete::encode(ByteWriter& w) const noexcept {
    w.u16(disk);
    w.u16(operation);
    write_name(w, directory_name);
    write_path(w, parent);
}

Result<DirectoryCreateDelete> DirectoryCreateDelete::decode(Bytes parameters) {
    ByteReader r(parameters);
    DirectoryCreateDelete c;
    c.disk = r.u16();
    c.operation = r.u16();
    c.directory_name = read_name(r);
    c.parent = read_path(r);
    return checked(std::move(c), r);
}

Result<DirectoryCreateDelete::Response> DirectoryCreateDelete::decode_response(Bytes data) const {
    return empty_response(data);
}

}  // namespace fins
