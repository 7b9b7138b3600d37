// File transfers 22 0A MEMORY AREA FILE TRANSFER, 22 0B PARAMETER AREA FILE TRANSFER and
// 22 0C PROGRAM AREA FILE TRANSFER (W342 5-3-39 .. 5-3-41, fins-frames 6 "22 xx"); the
// other file memory commands are file_memory.cpp's. Decoding follows its rules: 1002 short,
// 1001 bytes left over; any length mismatch in an answer is malformed_response.
#include "codec/command_codec.hpp"
#include "codec/commands/file_fields.hpp"
#include "fins/commands/file_memory.hpp"

namespace fins {

using codec::malformed;
using namespace codec::file_fields;

void FileTransferCountResponse::encode(ByteWriter& w) const noexcept {
    w.u16(count);
}

namespace {
Result<FileTransferCountResponse> count_response(Bytes data) {
    ByteReader r(data);
    FileTransferCountResponse out{r.u16()};
    if (r.truncated() || r.remaining() != 0) return malformed();
    return out;
}
}  // namespace

void MemoryAreaFileTransfer::encode(ByteWriter& w) const noexcept {
    w.u16(mode);
    w.u8(start.area_code);
    w.u16(start.word);
    w.u8(start.bit);
    w.u16(count);
    w.u16(disk);
    write_name(w, file);
    write_path(w, directory);
}

Result<MemoryAreaFileTransfer> MemoryAreaFileTransfer::decode(Bytes parameters) {
    ByteReader r(parameters);
    MemoryAreaFileTransfer c;
    c.mode = r.u16();
    c.start.area_code = r.u8();
    c.start.word = r.u16();
    c.start.bit = r.u8();
    c.count = r.u16();
    c.disk = r.u16();
    c.file = read_name(r);
    c.directory = read_path(r);
    return checked(std::move(c), r);
}

Result<MemoryAreaFileTransfer::Response> MemoryAreaFileTransfer::decode_response(Bytes data) const {
    return count_response(data);
}

void ParameterAreaFileTransfer::encode(ByteWriter& w) const noexcept {
    w.u16(mode);
    w.u16(area);
    w.u16(start);
    w.u16(count);
    w.u16(disk);
    write_name(w, file);
    write_path(w, directory);
}

Result<ParameterAreaFileTransfer> ParameterAreaFileTransfer::decode(Bytes parameters) {
    ByteReader r(parameters);
    ParameterAreaFileTransfer c;
    c.mode = r.u16();
    c.area = r.u16();
    c.start = r.u16();
    c.count = r.u16();
    c.disk = r.u16();
    c.file = read_name(r);
    c.directory = read_path(r);
    return checked(std::move(c), r);
}

Result<ParameterAreaFileTransfer::Response> ParameterAreaFileTransfer::decode_response(
    Bytes data) const {
    return count_response(data);
}

void ProgramAreaFileTransferResponse::encode(ByteWriter& w) const noexcept {
    w.u32(length);
}

void ProgramAreaFileTransfer::encode(ByteWriter& w) const noexcept {
    w.u16(mode);
    w.u16(program_number);
    w.u32(start);
    w.u32(length);
    w.u16(disk);
    write_name(w, file);
    write_path(w, directory);
}

Result<ProgramAreaFileTransfer> ProgramAreaFileTransfer::decode(Bytes parameters) {
    ByteReader r(parameters);
    ProgramAreaFileTransfer c;
    c.mode = r.u16();
    c.program_number = r.u16();
    c.start = r.u32();
    c.length = r.u32();
    c.disk = r.u16();
    c.file = read_name(r);
    c.directory = read_path(r);
    return checked(std::move(c), r);
}

Result<ProgramAreaFileTransfer::Response> ProgramAreaFileTransfer::decode_response(
    Bytes data) const {
    ByteReader r(data);
    ProgramAreaFileTransferResponse out{r.u32()};
    if (r.truncated() || r.remaining() != 0) return malformed();
    return out;
}

}  // namespace fins
