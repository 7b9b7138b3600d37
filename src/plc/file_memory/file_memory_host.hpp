// Private to plc::FileMemory: the host side of the file devices, on top of the host calls
// of file_memory_os.hpp (POSIX or Windows). Every helper works on directory handles and
// single, already-checked name components; none takes a path with a separator, and none
// follows a link.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "plc/file_memory/file_memory_os.hpp"

namespace fins::plc::host {

// An owned handle (file_memory_os.hpp).
class Fd {
  public:
    Fd() = default;
    explicit Fd(int fd) noexcept : fd_(fd) {}
    ~Fd() { host::close(fd_); }
    Fd(Fd&& other) noexcept : fd_(other.release()) {}
    Fd& operator=(Fd&& other) noexcept {
        if (this != &other) {
            host::close(fd_);
            fd_ = other.release();
        }
        return *this;
    }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    [[nodiscard]] int get() const noexcept { return fd_; }
    [[nodiscard]] bool valid() const noexcept { return fd_ >= 0; }
    int release() noexcept {
        const int fd = fd_;
        fd_ = -1;
        return fd;
    }

  private:
    int fd_ = -1;
};

struct Entry {
    std::string name;
    Kind kind = Kind::other;
    Info info;
};

// lstat-like, relative to `dir`.
Kind kind_of(int dir, const std::string& name, Info* info = nullptr) noexcept;
// What kind_of() says, without asking for the file's times: on Linux 6.13+ (multigrain
// timestamps) a stat that reads mtime makes the next write stamp a fine-grained time,
// which dirties the inode and journals it: about 15 us per 22 03 chunk instead of 2.
// kind, size, device and inode of `info` are filled, not mtime.
Kind identity_of(int dir, const std::string& name, Info* info) noexcept;
// Walks `components` from `dir`; invalid when one is missing, not a directory or a link.
Fd open_path(int dir, const std::vector<std::string>& components) noexcept;
// The entries of `dir` whose names `visible` accepts, sorted by name.
std::vector<Entry> entries(int dir, bool (*visible)(std::string_view name));
// Bytes of regular files below `dir` (hidden names included: temp files take room too).
std::uint64_t used_bytes(int dir, int depth = 0) noexcept;
// Removes everything below `dir`; with `only_temps`, only entries named ".tmp-*".
bool clear(int dir, bool only_temps, int depth = 0) noexcept;
// Whole regular file `name` (nullopt: missing or not a regular file, or unreadable).
std::optional<std::vector<std::uint8_t>> read_all(int dir, const std::string& name);
// Writes `content` to a new temp file in `dir`, syncs it, dates it `mtime`, renames it
// to `name` (replacing) and syncs `dir`. False on any host error (the temp is removed).
bool replace(int dir, const std::string& name, Bytes content, std::int64_t mtime,
             unsigned& counter) noexcept;
// Extending writes (22 03 0002, or 0003 at the file's end): `data` written at
// `old_size`, the file's size now, all of it or nothing. A write the host refuses part
// way (ENOSPC, EFBIG, EIO) is cut back to `old_size`, so the file stays exactly as the
// last acknowledged write left it (5-3-34: a refused write changes nothing). False on
// any host error.
// The regular file `name` in `dir` (opened without following a link), then dated.
bool extend_at(int dir, const std::string& name, std::uint64_t old_size, Bytes data,
               std::int64_t mtime) noexcept;
// An open handle of a regular file; the caller dates the file later.
bool extend_undated(int fd, std::uint64_t old_size, Bytes data) noexcept;
// Reads `size` bytes at `offset`, fewer only at the file's end; false on a host error.
bool read_fully(int fd, std::uint8_t* data, std::size_t size, std::uint64_t offset,
                std::size_t& done) noexcept;

}  // namespace fins::plc::host
