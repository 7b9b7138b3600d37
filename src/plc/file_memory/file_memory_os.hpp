// Private to plc::FileMemory: the host calls behind the file devices, one interface and
// two implementations. Everything above it (file_memory*.cpp, file_memory_host.cpp) is
// shared. A handle is an int: on POSIX a file descriptor, on Windows an index into the
// layer's table of HANDLEs, each with the final path it was verified at.
// Every call takes a directory handle and ONE name component that the caller has
// already checked (FileMemory's name rules, or a name finsd chose); none follows a link:
// - file_memory_os_posix.cpp: openat/fstatat/unlinkat/renameat with O_NOFOLLOW and
//   AT_SYMLINK_NOFOLLOW, so a symlink is never followed;
// - file_memory_os_win.cpp: CreateFileW (FILE_FLAG_OPEN_REPARSE_POINT |
//   FILE_FLAG_BACKUP_SEMANTICS) on "<directory's verified path>\<name>", then the opened
//   object is refused unless it is no reparse point (GetFileInformationByHandle) and its
//   final path (GetFinalPathNameByHandleW) is exactly that path: a symlink, junction or
//   mount point anywhere below the root is refused, and so is a Unix symlink under wine
//   (which follows links and reports only those to directories). Directories are held
//   without FILE_SHARE_DELETE, so Windows refuses to rename or remove one while it is open.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace fins::plc::host {

enum class Kind : std::uint8_t { missing, file, directory, other };

// What FileMemory needs of a host entry (times: seconds since 1970 of the CPU clock).
struct Info {
    Kind kind = Kind::missing;
    std::uint64_t size = 0;
    std::int64_t mtime = 0;
    std::uint64_t device = 0;  // with inode: the same file, while it exists
    std::uint64_t inode = 0;
};

enum class Status : std::uint8_t { ok, exists, not_empty, failed };
enum class Access : std::uint8_t { read, write, read_write };

void close(int handle) noexcept;
int duplicate(int handle) noexcept;
// The root, given by finsd's operator: links in its path are followed.
int open_root(const std::filesystem::path& root, std::error_code& error) noexcept;
// A device directory (<root>/card ...) that is a link: opened following it, once.
bool is_link(int dir, const std::string& name) noexcept;
int open_linked_directory(int dir, const std::string& name, std::error_code& error) noexcept;
// The sub-directory `name`; -1 when missing, not a directory or a link.
int open_directory(int dir, const std::string& name) noexcept;
// lstat-like; `times`: fill `mtime` too (Linux: a stat that reads mtime costs a later
// write a fine-grained timestamp, see file_memory_host.hpp).
Kind stat_at(int dir, const std::string& name, Info* info, bool times) noexcept;
bool stat(int handle, Info& info) noexcept;
// An existing regular file; -1 when missing, not a regular file or a link.
int open_file(int dir, const std::string& name, Access access) noexcept;
// A new regular file for writing; -1 with `exists` set when the name is taken.
int create_file(int dir, const std::string& name, bool& exists) noexcept;
// The names in `dir` other than "." and "..", unsorted.
std::vector<std::string> names(int dir);
Status make_directory(int dir, const std::string& name) noexcept;
// A file (a link itself, never its target) or an empty directory.
Status remove(int dir, const std::string& name, bool directory) noexcept;
// Within one directory, replacing `to`.
bool rename(int dir, const std::string& from, const std::string& to) noexcept;
// Bytes transferred (0: end of file), or -1.
long long read_at(int handle, std::uint8_t* data, std::size_t size, std::uint64_t offset) noexcept;
long long write_at(int handle, const std::uint8_t* data, std::size_t size,
                   std::uint64_t offset) noexcept;
bool truncate(int handle, std::uint64_t size) noexcept;
// fsync (a directory too on POSIX; NTFS journals directories: true there).
bool sync(int handle) noexcept;
bool set_mtime(int handle, std::int64_t mtime) noexcept;
bool set_mtime_at(int dir, const std::string& name, std::int64_t mtime) noexcept;
// A new private directory under the host's temp directory.
std::filesystem::path make_temp_directory(std::error_code& error);
unsigned process_id() noexcept;

}  // namespace fins::plc::host
