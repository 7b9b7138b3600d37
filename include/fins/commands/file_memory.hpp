// File memory commands 22 01 .. 22 15 (W342 5-3-32 .. 5-3-42, fins-frames 6 "22 xx",
// frames-serial-files 4).
//
// The same command-type shape as fins/commands/memory_area.hpp. Names and directory
// paths travel as the bytes the manual lays out (a 12-byte 8.3 name padded with 20 hex,
// a 2-byte length plus ASCII path); the codec only frames them, the virtual PLC checks
// them (plc/file_memory.hpp) so that a hostile name reaches no decision but its end code.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// Disk numbers (5-3-32): memory card, EM file memory; 8003 Memory Cassette (22 20 only).
inline constexpr std::uint16_t disk_memory_card = 0x8000;
inline constexpr std::uint16_t disk_em_file = 0x8001;
inline constexpr std::uint16_t disk_memory_cassette = 0x8003;

// 5-3-32: at most 20 (14 hex) file entries per FILE NAME READ.
inline constexpr std::uint16_t max_file_entries = 20;
// Bit 15 of 22 01's number of files and of 22 02's data length: "the last is included".
inline constexpr std::uint16_t file_last_bit = 0x8000;
// 5-3-32 .. 5-3-42: "The maximum number of characters is 65" for a directory path.
inline constexpr std::size_t max_directory_path = 65;
// A 22 02 response: file capacity (4), position (4), data length (2), then the data,
// inside the 1,998 response bytes after the end code.
inline constexpr std::uint16_t max_file_read_bytes = 1988;
// Bytes of disk data before the entries of a 22 01 response; bytes per entry.
inline constexpr std::size_t disk_data_size = 26;
inline constexpr std::size_t file_entry_size = 22;
// 5-3-39 .. 5-3-41 data files (.IOM, .STD, .OBJ) start with a 48-byte header
// (CJ2SW p.269/272); finskit writes zeros there and skips it on load.
inline constexpr std::size_t data_file_header_size = 48;

// The 12-byte name of 5-1 "Volume Labels and File Names": 8 name characters, ".",
// 3 extension characters, left-aligned, padded with 20 hex; no extension: "." and the
// extension are 20 hex too.
struct FileName {
    std::array<std::uint8_t, 12> bytes{};

    // "AUTOEXEC.IOM" -> 12 bytes. Only lays the text out (8 + 3 characters at most, one
    // dot); the characters themselves are the PLC's to check. nullopt when it cannot
    // be laid out.
    static std::optional<FileName> from(std::string_view text) noexcept;
    // The name without padding ("AUTOEXEC.IOM", "DATA"); bytes as they are.
    [[nodiscard]] std::string text() const;
    friend bool operator==(const FileName&, const FileName&) = default;
};

// 22 01 file data: name, date (FAT packing, 5-3-32 note), size, attribute.
inline constexpr std::uint16_t attribute_read_only = 0x01;
inline constexpr std::uint16_t attribute_hidden = 0x02;
inline constexpr std::uint16_t attribute_system = 0x04;
inline constexpr std::uint16_t attribute_volume = 0x08;
inline constexpr std::uint16_t attribute_directory = 0x10;
inline constexpr std::uint16_t attribute_archive = 0x20;

struct FileEntry {
    FileName name;
    std::uint32_t date = 0;  // bits 31-25 year-1980, 24-21 month, 20-16 day, 15-11 hour,
                             // 10-5 minute, 4-0 second/2
    std::uint32_t size = 0;
    std::uint16_t attribute = 0;
    friend bool operator==(const FileEntry&, const FileEntry&) = default;
};

struct DiskData {
    FileName volume_label;
    std::uint32_t date = 0;
    std::uint32_t total_capacity = 0;
    std::uint32_t free_capacity = 0;
    std::uint16_t total_files = 0;  // in the directory, "." and ".." included
    friend bool operator==(const DiskData&, const DiskData&) = default;
};

// FAT date/time packing of 5-3-32 (year 1980-2107).
std::uint32_t pack_file_date(int year, unsigned month, unsigned day, unsigned hour, unsigned minute,
                             unsigned second) noexcept;

// A whole directory as the client's list_directory() gathers it over several 22 01s.
struct DirectoryListing {
    DiskData disk;
    std::vector<FileEntry> files;
};

struct FileNameReadResponse {
    DiskData disk;
    bool last = false;  // bit 15 of the number of files
    std::vector<FileEntry> files;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const FileNameReadResponse&, const FileNameReadResponse&) = default;
};

struct FileNameRead {
    static constexpr CommandCode code{0x22, 0x01};
    static constexpr std::string_view name = "FILE NAME READ";
    using Response = FileNameReadResponse;

    std::uint16_t disk = disk_memory_card;
    std::uint16_t first = 0;  // beginning file position
    std::uint16_t count = 0;  // 0-20; 0 with first 0: disk data only
    std::string directory;    // "" = root, else "\DIR\SUB"

    void encode(ByteWriter& w) const noexcept;
    // 1002 shorter than 8 bytes or than the path length says, 1001 longer.
    static Result<FileNameRead> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

struct SingleFileReadResponse {
    std::uint32_t file_size = 0;
    std::uint32_t position = 0;
    bool last = false;  // bit 15 of the data length: the file's last byte is included
    std::vector<std::uint8_t> data;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const SingleFileReadResponse&, const SingleFileReadResponse&) = default;
};

struct SingleFileRead {
    static constexpr CommandCode code{0x22, 0x02};
    static constexpr std::string_view name = "SINGLE FILE READ";
    using Response = SingleFileReadResponse;

    std::uint16_t disk = disk_memory_card;
    FileName file;
    std::uint32_t position = 0;
    std::uint16_t length = 0;  // at most max_file_read_bytes
    std::string directory;

    void encode(ByteWriter& w) const noexcept;
    static Result<SingleFileRead> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

// 5-3-34 parameter codes.
enum class FileWriteMode : std::uint16_t {
    create = 0x0000,             // new file; an existing one is kept (2107)
    create_or_replace = 0x0001,  // new file; an existing one is replaced
    append = 0x0002,             // add to an existing file
    overwrite = 0x0003,          // overwrite an existing file from `position`
};

struct SingleFileWrite {
    static constexpr CommandCode code{0x22, 0x03};
    static constexpr std::string_view name = "SINGLE FILE WRITE";
    using Response = EmptyResponse;

    std::uint16_t disk = disk_memory_card;
    std::uint16_t mode = static_cast<std::uint16_t>(FileWriteMode::create);
    FileName file;
    std::uint32_t position = 0;
    Bytes data;  // a view, the caller keeps it alive
    std::string directory;

    void encode(ByteWriter& w) const noexcept;
    // 1002 when the data or path is shorter than its length field says, 1001 longer.
    static Result<SingleFileWrite> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

struct FileMemoryFormat {
    static constexpr CommandCode code{0x22, 0x04};
    static constexpr std::string_view name = "FILE MEMORY FORMAT";
    using Response = EmptyResponse;
    std::uint16_t disk = disk_memory_card;
    void encode(ByteWriter& w) const noexcept;
    static Result<FileMemoryFormat> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

struct FileDeleteResponse {
    std::uint16_t deleted = 0;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const FileDeleteResponse&, const FileDeleteResponse&) = default;
};

struct FileDelete {
    static constexpr CommandCode code{0x22, 0x05};
    static constexpr std::string_view name = "FILE DELETE";
    using Response = FileDeleteResponse;
    std::uint16_t disk = disk_memory_card;
    std::vector<FileName> files;
    std::string directory;
    void encode(ByteWriter& w) const noexcept;
    static Result<FileDelete> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

struct FileCopy {
    static constexpr CommandCode code{0x22, 0x07};
    static constexpr std::string_view name = "FILE COPY";
    using Response = EmptyResponse;
    std::uint16_t source_disk = disk_memory_card;
    FileName source;
    std::uint16_t destination_disk = disk_memory_card;
    FileName destination;
    std::string source_directory;
    std::string destination_directory;
    void encode(ByteWriter& w) const noexcept;
    static Result<FileCopy> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

struct FileNameChange {
    static constexpr CommandCode code{0x22, 0x08};
    static constexpr std::string_view name = "FILE NAME CHANGE";
    using Response = EmptyResponse;
    std::uint16_t disk = disk_memory_card;
    FileName old_name;
    FileName new_name;
    std::string directory;
    void encode(ByteWriter& w) const noexcept;
    static Result<FileNameChange> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

// 5-3-39 .. 5-3-41 parameter codes.
enum class FileTransferMode : std::uint16_t {
    to_file = 0x0000,    // area -> file (never overwrites: 2107)
    from_file = 0x0001,  // file -> area
    compare = 0x0002,
};

// 22 0A / 22 0B: number of items transferred or compared (22 0B compare: the position of
// the first mismatch).
struct FileTransferCountResponse {
    std::uint16_t count = 0;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const FileTransferCountResponse&,
                           const FileTransferCountResponse&) = default;
};

struct MemoryAreaFileTransfer {
    static constexpr CommandCode code{0x22, 0x0A};
    static constexpr std::string_view name = "MEMORY AREA-FILE TRANSFER";
    using Response = FileTransferCountResponse;
    std::uint16_t mode = 0;
    MemoryAddress start;  // word areas only (5-3-39 table)
    std::uint16_t count = 0;
    std::uint16_t disk = disk_memory_card;
    FileName file;
    std::string directory;
    void encode(ByteWriter& w) const noexcept;
    static Result<MemoryAreaFileTransfer> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

inline constexpr std::uint16_t whole_parameter_area = 0xFFFF;

struct ParameterAreaFileTransfer {
    static constexpr CommandCode code{0x22, 0x0B};
    static constexpr std::string_view name = "PARAMETER AREA-FILE TRANSFER";
    using Response = FileTransferCountResponse;
    std::uint16_t mode = 0;
    std::uint16_t area = 0x8010;
    std::uint16_t start = 0;                     // always 0000
    std::uint16_t count = whole_parameter_area;  // always FFFF
    std::uint16_t disk = disk_memory_card;
    FileName file;
    std::string directory;
    void encode(ByteWriter& w) const noexcept;
    static Result<ParameterAreaFileTransfer> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

struct ProgramAreaFileTransferResponse {
    std::uint32_t length = 0;  // bytes transferred / compared
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const ProgramAreaFileTransferResponse&,
                           const ProgramAreaFileTransferResponse&) = default;
};

struct ProgramAreaFileTransfer {
    static constexpr CommandCode code{0x22, 0x0C};
    static constexpr std::string_view name = "PROGRAM AREA-FILE TRANSFER";
    using Response = ProgramAreaFileTransferResponse;
    std::uint16_t mode = 0;
    std::uint16_t program_number = 0xFFFF;
    std::uint32_t start = 0;            // always 00000000
    std::uint32_t length = 0xFFFFFFFF;  // always FFFFFFFF
    std::uint16_t disk = disk_memory_card;
    FileName file;
    std::string directory;
    void encode(ByteWriter& w) const noexcept;
    static Result<ProgramAreaFileTransfer> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

enum class DirectoryOperation : std::uint16_t { create = 0x0000, remove = 0x0001 };

struct DirectoryCreateDelete {
    static constexpr CommandCode code{0x22, 0x15};
    static constexpr std::string_view name = "CREATE/DELETE DIRECTORY";
    using Response = EmptyResponse;
    std::uint16_t disk = disk_memory_card;
    std::uint16_t operation = 0;
    FileName directory_name;
    std::string parent;  // absolute path of the parent; "" = root
    void encode(ByteWriter& w) const noexcept;
    static Result<DirectoryCreateDelete> decode(Bytes parameters);
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
