// The state file's host calls on Linux (contract in storage_os.hpp).
#ifndef _WIN32
#include <fcntl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include "plc/storage/storage_os.hpp"

namespace fins::plc::state_file::os {

namespace {

int fd(Handle h) noexcept {
    return static_cast<int>(h);
}

}  // namespace

Directory::~Directory() {
    if (handle != none) ::close(fd(handle));
}

std::error_code last_error() noexcept {
    return {errno, std::system_category()};
}

bool is_lock_conflict(const std::error_code& e) noexcept {
    return e == std::error_code(EWOULDBLOCK, std::system_category());
}

bool is_missing(const std::error_code& e) noexcept {
    return e == std::error_code(ENOENT, std::system_category());
}

bool is_no_space(const std::error_code& e) noexcept {
    if (e.category() != std::system_category()) return false;
    return e.value() == ENOSPC || e.value() == EDQUOT || e.value() == EFBIG;
}

Result<void> lock_directory(const std::filesystem::path& path, Directory& dir) {
    dir.path = path;
    const int d = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (d < 0) return Unexpected(last_error());
    dir.handle = d;
    if (::flock(d, LOCK_EX | LOCK_NB) != 0) return Unexpected(last_error());
    return {};
}

Result<Handle> open_file(const Directory& dir, const char* name) {
    const int f = ::openat(fd(dir.handle), name, O_RDWR | O_CLOEXEC);
    if (f < 0) return Unexpected(last_error());
    return Handle{f};
}

Result<Handle> create_file(const Directory& dir, const char* name) {
    const int f = ::openat(fd(dir.handle), name, O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (f < 0) return Unexpected(last_error());
    return Handle{f};
}

void close(Handle file) noexcept {
    if (file != none) ::close(fd(file));
}

Result<bool> exists(const Directory& dir, const char* name) {
    struct stat st {};
    if (::fstatat(fd(dir.handle), name, &st, AT_SYMLINK_NOFOLLOW) == 0) return true;
    if (errno != ENOENT) return Unexpected(last_error());
    return false;
}

Result<void> rename(const Directory& dir, const char* from, const char* to) {
    if (::renameat(fd(dir.handle), from, fd(dir.handle), to) != 0) return Unexpected(last_error());
    return {};
}

Result<void> link(const Directory& dir, const char* from, const char* to) {
    if (::linkat(fd(dir.handle), from, fd(dir.handle), to, 0) != 0) return Unexpected(last_error());
    return {};
}

void remove(const Directory& dir, const char* name) noexcept {
    ::unlinkat(fd(dir.handle), name, 0);
}

Result<void> sync(const Directory& dir) {
    if (::fsync(fd(dir.handle)) != 0) return Unexpected(last_error());
    return {};
}

Result<std::uint64_t> size(Handle file) {
    struct stat st {};
    if (::fstat(fd(file), &st) != 0) return Unexpected(last_error());
    return static_cast<std::uint64_t>(st.st_size);
}

std::error_code reserve(Handle file, std::uint64_t offset, std::uint64_t length) noexcept {
    const int e =
        ::posix_fallocate(fd(file), static_cast<off_t>(offset), static_cast<off_t>(length));
    return e == 0 ? std::error_code{} : std::error_code(e, std::system_category());
}

long long read_at(Handle file, void* buffer, std::size_t n, std::uint64_t offset) noexcept {
    return ::pread(fd(file), buffer, n, static_cast<off_t>(offset));
}

long long write_at(Handle file, const void* buffer, std::size_t n, std::uint64_t offset) noexcept {
    return ::pwrite(fd(file), buffer, n, static_cast<off_t>(offset));
}

Result<View> map(Handle file, std::uint64_t offset, std::size_t length, bool writable) {
    void* p = ::mmap(nullptr, length, writable ? PROT_READ | PROT_WRITE : PROT_READ, MAP_SHARED,
                     fd(file), static_cast<off_t>(offset));
    if (p == MAP_FAILED) return Unexpected(last_error());
    return View{p, length, static_cast<std::byte*>(p)};
}

void unmap(void* base, std::size_t span) noexcept {
    ::munmap(base, span);
}

void flush(void* base, std::size_t span) noexcept {
    ::msync(base, span, MS_SYNC);
}

bool sync_data(Handle file, std::span<const std::pair<void*, std::size_t>>,
               std::pair<void*, std::size_t>) noexcept {
    return ::fdatasync(fd(file)) == 0;
}

void* reserve_zeroed(std::size_t length) noexcept {
    void* p = ::mmap(nullptr, length, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    return p == MAP_FAILED ? nullptr : p;
}

void release_zeroed(void* p, std::size_t length) noexcept {
    ::munmap(p, length);
}

}  // namespace fins::plc::state_file::os
#endif
