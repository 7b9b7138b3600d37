// plc::FileMemory's host calls on POSIX (see file_memory_os.hpp): *at calls that never
// follow a symlink (O_NOFOLLOW, AT_SYMLINK_NOFOLLOW).
#ifndef _WIN32
#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>

#include "plc/file_memory/file_memory_os.hpp"

namespace fins::plc::host {

namespace {

timespec at(std::int64_t seconds) noexcept {
    timespec t{};
    t.tv_sec = static_cast<time_t>(seconds);
    return t;
}

Kind kind_of_mode(mode_t mode) noexcept {
    if (S_ISREG(mode)) return Kind::file;
    if (S_ISDIR(mode)) return Kind::directory;
    return Kind::other;
}

}  // namespace

void close(int handle) noexcept {
    if (handle >= 0) ::close(handle);
}

int duplicate(int handle) noexcept {
    return ::fcntl(handle, F_DUPFD_CLOEXEC, 0);
}

int open_root(const std::filesystem::path& root, std::error_code& error) noexcept {
    const int fd = ::open(root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) error = std::error_code(errno, std::generic_category());
    return fd;
}

bool is_link(int dir, const std::string& name) noexcept {
    struct stat st {};
    return ::fstatat(dir, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(st.st_mode);
}

int open_linked_directory(int dir, const std::string& name, std::error_code& error) noexcept {
    const int fd = ::openat(dir, name.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) error = std::error_code(errno, std::generic_category());
    return fd;
}

int open_directory(int dir, const std::string& name) noexcept {
    return ::openat(dir, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
}

Kind stat_at(int dir, const std::string& name, Info* info, bool times) noexcept {
    if (times) {
        struct stat st {};
        if (::fstatat(dir, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) return Kind::missing;
        const Kind kind = kind_of_mode(st.st_mode);
        if (info != nullptr)
            *info = {kind, static_cast<std::uint64_t>(st.st_size), st.st_mtime,
                     static_cast<std::uint64_t>(st.st_dev), static_cast<std::uint64_t>(st.st_ino)};
        return kind;
    }
    struct statx sx {};
    if (::statx(dir, name.c_str(), AT_SYMLINK_NOFOLLOW,
                STATX_TYPE | STATX_MODE | STATX_INO | STATX_SIZE, &sx) != 0)
        return Kind::missing;
    const Kind kind = kind_of_mode(sx.stx_mode);
    if (info != nullptr)
        *info = {kind, sx.stx_size, 0, makedev(sx.stx_dev_major, sx.stx_dev_minor), sx.stx_ino};
    return kind;
}

bool stat(int handle, Info& info) noexcept {
    struct stat st {};
    if (::fstat(handle, &st) != 0) return false;
    info = {kind_of_mode(st.st_mode), static_cast<std::uint64_t>(st.st_size), st.st_mtime,
            static_cast<std::uint64_t>(st.st_dev), static_cast<std::uint64_t>(st.st_ino)};
    return true;
}

int open_file(int dir, const std::string& name, Access access) noexcept {
    const int flags = access == Access::read    ? O_RDONLY
                      : access == Access::write ? O_WRONLY
                                                : O_RDWR;
    const int fd = ::openat(dir, name.c_str(), flags | O_NOFOLLOW | O_CLOEXEC);
    struct stat st {};
    if (fd >= 0 && (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))) {
        ::close(fd);
        return -1;
    }
    return fd;
}

int create_file(int dir, const std::string& name, bool& exists) noexcept {
    const int fd =
        ::openat(dir, name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    exists = fd < 0 && errno == EEXIST;
    return fd;
}

std::vector<std::string> names(int dir) {
    std::vector<std::string> out;
    const int fd = duplicate(dir);
    if (fd < 0) return out;
    DIR* d = ::fdopendir(fd);
    if (d == nullptr) {
        ::close(fd);
        return out;
    }
    ::rewinddir(d);
    while (const dirent* e = ::readdir(d)) {
        const std::string_view name = e->d_name;
        if (name != "." && name != "..") out.emplace_back(name);
    }
    ::closedir(d);
    return out;
}

Status make_directory(int dir, const std::string& name) noexcept {
    if (::mkdirat(dir, name.c_str(), 0755) == 0) return Status::ok;
    return errno == EEXIST ? Status::exists : Status::failed;
}

Status remove(int dir, const std::string& name, bool directory) noexcept {
    if (::unlinkat(dir, name.c_str(), directory ? AT_REMOVEDIR : 0) == 0) return Status::ok;
    return errno == ENOTEMPTY || errno == EEXIST ? Status::not_empty : Status::failed;
}

bool rename(int dir, const std::string& from, const std::string& to) noexcept {
    return ::renameat(dir, from.c_str(), dir, to.c_str()) == 0;
}

long long read_at(int handle, std::uint8_t* data, std::size_t size, std::uint64_t offset) noexcept {
    for (;;) {
        const auto n = ::pread(handle, data, size, static_cast<off_t>(offset));
        if (n < 0 && errno == EINTR) continue;
        return n;
    }
}

long long write_at(int handle, const std::uint8_t* data, std::size_t size,
                   std::uint64_t offset) noexcept {
    for (;;) {
        const auto n = ::pwrite(handle, data, size, static_cast<off_t>(offset));
        if (n < 0 && errno == EINTR) continue;
        return n;
    }
}

bool truncate(int handle, std::uint64_t size) noexcept {
    const int saved = errno;  // the caller reports the write's error, not this one's
    int rc = 0;
    while ((rc = ::ftruncate(handle, static_cast<off_t>(size))) != 0 && errno == EINTR) {
    }
    errno = saved;
    return rc == 0;
}

bool sync(int handle) noexcept {
    return ::fsync(handle) == 0;
}

bool set_mtime(int handle, std::int64_t mtime) noexcept {
    const timespec times[2] = {at(mtime), at(mtime)};
    return ::futimens(handle, times) == 0;
}

bool set_mtime_at(int dir, const std::string& name, std::int64_t mtime) noexcept {
    const timespec times[2] = {at(mtime), at(mtime)};
    return ::utimensat(dir, name.c_str(), times, AT_SYMLINK_NOFOLLOW) == 0;
}

std::filesystem::path make_temp_directory(std::error_code& error) {
    std::string pattern = (std::filesystem::temp_directory_path() / "finsd-files-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
        error = std::error_code(errno, std::generic_category());
        return {};
    }
    return pattern;
}

unsigned process_id() noexcept {
    return static_cast<unsigned>(::getpid());
}

}  // namespace fins::plc::host
#endif
