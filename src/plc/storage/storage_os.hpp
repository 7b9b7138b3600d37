// The host calls behind the state file (storage.cpp, storage_format.cpp,
// storage_upgrade.cpp, storage_chunks.cpp): one interface, two implementations.
// storage_os_posix.cpp is what Linux always did (openat, flock, posix_fallocate, mmap
// MAP_SHARED, fdatasync, renameat, linkat, directory fsync); storage_os_win.cpp does the
// same on Windows (docs/windows.md):
// - the data directory is locked with LockFileEx on `<dir>/finsd.lock` (a directory
//   cannot be locked there): a second finsd gets "in use", as with flock;
// - files are opened without FILE_SHARE_WRITE, so nothing else can write or truncate
//   the state file while finsd maps it (and Windows refuses to shrink a mapped file);
// - a reservation extends the file (SetEndOfFile: NTFS allocates the clusters of a file
//   that is not sparse), a full disk is no_space at start as with posix_fallocate;
// - views come from CreateFileMapping/MapViewOfFile at 64 KiB-aligned offsets (the
//   allocation granularity; sections are 4 KiB-aligned in the file);
// - a view of a file lives in the system cache: a write to it survives the end of the
//   process (TerminateProcess, a crash) as MAP_SHARED does on Linux; sync_data() is
//   FlushViewOfFile on every view then FlushFileBuffers (power loss);
// - rename and link are MoveFileExW (MOVEFILE_WRITE_THROUGH) and CreateHardLinkW;
//   NTFS journals its metadata, so a directory needs no sync of its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <system_error>
#include <utility>

#include "fins/error.hpp"

namespace fins::plc::state_file::os {

// A file descriptor on POSIX, a HANDLE on Windows.
using Handle = std::intptr_t;
inline constexpr Handle none = -1;

// The data directory, locked for the object's life.
struct Directory {
    Handle handle = none;  // POSIX: the directory (flocked); Windows: finsd.lock (locked)
    std::filesystem::path path;
    Directory() = default;
    ~Directory();
    Directory(const Directory&) = delete;
    Directory& operator=(const Directory&) = delete;
    [[nodiscard]] bool valid() const noexcept { return handle != none; }
};

// The last host error (errno, GetLastError()).
std::error_code last_error() noexcept;
// True when `e` says another process holds the lock.
bool is_lock_conflict(const std::error_code& e) noexcept;
// True when `e` says the name does not exist.
bool is_missing(const std::error_code& e) noexcept;
// True when `e` says the disk (or quota, or the largest file) is full.
bool is_no_space(const std::error_code& e) noexcept;

// Opens `path` (an existing directory) into `dir` and locks it without waiting.
Result<void> lock_directory(const std::filesystem::path& path, Directory& dir);
// `name` in `dir`, read-write: an existing file, or a new empty one (truncated).
Result<Handle> open_file(const Directory& dir, const char* name);
Result<Handle> create_file(const Directory& dir, const char* name);
void close(Handle file) noexcept;
// Whether `name` exists in `dir` (without following a link).
Result<bool> exists(const Directory& dir, const char* name);
// `from` renamed to `to` in `dir`, replacing it.
Result<void> rename(const Directory& dir, const char* from, const char* to);
// A second name `to` for `from`; fails when `to` exists.
Result<void> link(const Directory& dir, const char* from, const char* to);
void remove(const Directory& dir, const char* name) noexcept;
// The directory's entries on disk (fsync on POSIX; nothing to do on Windows).
Result<void> sync(const Directory& dir);

Result<std::uint64_t> size(Handle file);
// Every byte of [offset, offset + length) reserved on disk (the file grows if needed).
std::error_code reserve(Handle file, std::uint64_t offset, std::uint64_t length) noexcept;
// Positional reads and writes: bytes done, or -1.
long long read_at(Handle file, void* buffer, std::size_t n, std::uint64_t offset) noexcept;
long long write_at(Handle file, const void* buffer, std::size_t n, std::uint64_t offset) noexcept;

// A shared view of `length` bytes at `offset` (a multiple of 4 KiB). `base` and `span`
// are what unmap() and flush() take; `data` is the byte at `offset`.
struct View {
    void* base = nullptr;
    std::size_t span = 0;
    std::byte* data = nullptr;
};
Result<View> map(Handle file, std::uint64_t offset, std::size_t length, bool writable);
void unmap(void* base, std::size_t span) noexcept;
// A view's pages to disk now (msync, FlushViewOfFile).
void flush(void* base, std::size_t span) noexcept;
// The file's data on disk, `views` and `header` (base, span; nullptr: none) included:
// fdatasync on POSIX (it covers MAP_SHARED pages); FlushViewOfFile on each view then
// FlushFileBuffers on Windows.
bool sync_data(Handle file, std::span<const std::pair<void*, std::size_t>> views,
               std::pair<void*, std::size_t> header) noexcept;

// Zeroed private memory backed lazily (an anonymous MAP_NORESERVE mapping, VirtualAlloc).
void* reserve_zeroed(std::size_t length) noexcept;
void release_zeroed(void* p, std::size_t length) noexcept;

}  // namespace fins::plc::state_file::os
