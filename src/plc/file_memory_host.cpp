// Host file-system helpers of plc::FileMemory (see file_memory_host.hpp).
// Linux (POSIX *at calls); Windows: file_memory_win.cpp.
#ifndef _WIN32
#include "plc/file_memory_host.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <string>

namespace fins::plc::host {

namespace {

constexpr int max_depth = 16;  // host trees deeper than FINS allows are not walked further
constexpr std::string_view temp_prefix = ".tmp-";

bool write_fully(int fd, Bytes data, off_t offset) noexcept {
    std::size_t done = 0;
    while (done < data.size()) {
        const auto n =
            ::pwrite(fd, data.data() + done, data.size() - done, offset + static_cast<off_t>(done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        done += static_cast<std::size_t>(n);
    }
    return true;
}

timespec at(std::int64_t seconds) noexcept {
    timespec t{};
    t.tv_sec = static_cast<time_t>(seconds);
    return t;
}

}  // namespace

Fd::~Fd() {
    if (fd_ >= 0) ::close(fd_);
}

Fd& Fd::operator=(Fd&& other) noexcept {
    if (this != &other) {
        if (fd_ >= 0) ::close(fd_);
        fd_ = other.release();
    }
    return *this;
}

Kind kind_of(int dir, const std::string& name, struct stat* info) noexcept {
    struct stat st {};
    if (::fstatat(dir, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) return Kind::missing;
    if (info != nullptr) *info = st;
    if (S_ISREG(st.st_mode)) return Kind::file;
    if (S_ISDIR(st.st_mode)) return Kind::directory;
    return Kind::other;
}

Kind identity_of(int dir, const std::string& name, struct stat* info) noexcept {
    struct statx sx {};
    if (::statx(dir, name.c_str(), AT_SYMLINK_NOFOLLOW,
                STATX_TYPE | STATX_MODE | STATX_INO | STATX_SIZE, &sx) != 0)
        return Kind::missing;
    if (info != nullptr) {
        *info = {};
        info->st_mode = sx.stx_mode;
        info->st_ino = sx.stx_ino;
        info->st_dev = makedev(sx.stx_dev_major, sx.stx_dev_minor);
        info->st_size = static_cast<off_t>(sx.stx_size);
    }
    if (S_ISREG(sx.stx_mode)) return Kind::file;
    if (S_ISDIR(sx.stx_mode)) return Kind::directory;
    return Kind::other;
}

Fd open_directory(int dir, const std::string& name) noexcept {
    return Fd(::openat(dir, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
}

Fd open_path(int dir, const std::vector<std::string>& components) noexcept {
    Fd current(::dup(dir));
    for (const auto& c : components) {
        if (!current.valid()) return current;
        current = open_directory(current.get(), c);
    }
    return current;
}

std::vector<Entry> entries(int dir, bool (*visible)(std::string_view name)) {
    std::vector<Entry> out;
    const int fd = ::dup(dir);
    if (fd < 0) return out;
    DIR* d = ::fdopendir(fd);
    if (d == nullptr) {
        ::close(fd);
        return out;
    }
    ::rewinddir(d);
    while (const dirent* e = ::readdir(d)) {
        const std::string_view name = e->d_name;
        if (!visible(name)) continue;
        Entry entry;
        entry.name = std::string(name);
        entry.kind = kind_of(dir, entry.name, &entry.info);
        if (entry.kind == Kind::file || entry.kind == Kind::directory)
            out.push_back(std::move(entry));
    }
    ::closedir(d);
    std::sort(out.begin(), out.end(),
              [](const Entry& a, const Entry& b) { return a.name < b.name; });
    return out;
}

std::uint64_t used_bytes(int dir, int depth) noexcept {
    if (depth > max_depth) return 0;
    std::uint64_t total = 0;
    try {
        for (const auto& e :
             entries(dir, [](std::string_view n) { return n != "." && n != ".."; })) {
            if (e.kind == Kind::file) {
                total += static_cast<std::uint64_t>(e.info.st_size);
            } else if (e.kind == Kind::directory) {
                const Fd sub = open_directory(dir, e.name);
                if (sub.valid()) total += used_bytes(sub.get(), depth + 1);
            }
        }
    } catch (...) {
    }
    return total;
}

bool clear(int dir, bool only_temps, int depth) noexcept {
    if (depth > max_depth) return false;
    bool ok = true;
    try {
        for (const auto& e :
             entries(dir, [](std::string_view n) { return n != "." && n != ".."; })) {
            const bool temp = e.name.starts_with(temp_prefix);
            if (e.kind == Kind::directory) {
                const Fd sub = open_directory(dir, e.name);
                if (sub.valid()) ok = clear(sub.get(), only_temps, depth + 1) && ok;
                if (!only_temps && ::unlinkat(dir, e.name.c_str(), AT_REMOVEDIR) != 0) ok = false;
            } else if (!only_temps || temp) {
                if (::unlinkat(dir, e.name.c_str(), 0) != 0) ok = false;
            }
        }
    } catch (...) {
        return false;
    }
    return ok;
}

std::optional<std::vector<std::uint8_t>> read_all(int dir, const std::string& name) {
    const Fd fd(::openat(dir, name.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC));
    if (!fd.valid()) return std::nullopt;
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
    std::vector<std::uint8_t> out(static_cast<std::size_t>(st.st_size));
    std::size_t done = 0;
    while (done < out.size()) {
        const auto n =
            ::pread(fd.get(), out.data() + done, out.size() - done, static_cast<off_t>(done));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return std::nullopt;
        if (n == 0) break;
        done += static_cast<std::size_t>(n);
    }
    out.resize(done);
    return out;
}

bool set_mtime(int dir, const char* name, std::int64_t mtime) noexcept {
    const timespec times[2] = {at(mtime), at(mtime)};
    return ::utimensat(dir, name, times, AT_SYMLINK_NOFOLLOW) == 0;
}

bool replace(int dir, const std::string& name, Bytes content, std::int64_t mtime,
             unsigned& counter) noexcept {
    std::string temp;
    Fd fd;
    for (int attempt = 0; attempt < 100 && !fd.valid(); ++attempt) {
        temp =
            std::string(temp_prefix) + std::to_string(::getpid()) + "-" + std::to_string(counter++);
        fd = Fd(::openat(dir, temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                         0644));
        if (!fd.valid() && errno != EEXIST) return false;
    }
    if (!fd.valid()) return false;
    const timespec times[2] = {at(mtime), at(mtime)};
    const bool ok = write_fully(fd.get(), content, 0) && ::fsync(fd.get()) == 0 &&
                    ::futimens(fd.get(), times) == 0 &&
                    ::renameat(dir, temp.c_str(), dir, name.c_str()) == 0;
    if (!ok) {
        ::unlinkat(dir, temp.c_str(), 0);
        return false;
    }
    ::fsync(dir);
    return true;
}

bool extend_undated(int fd, std::uint64_t old_size, Bytes data) noexcept {
    if (write_fully(fd, data, static_cast<off_t>(old_size))) return true;
    // The bytes that fitted before the host refused the rest would make the file larger
    // than any acknowledged write: a client resuming at 22 02's size would skip data.
    const int saved = errno;
    while (::ftruncate(fd, static_cast<off_t>(old_size)) != 0 && errno == EINTR) {
    }
    errno = saved;
    return false;
}

bool set_mtime_fd(int fd, std::int64_t mtime) noexcept {
    const timespec times[2] = {at(mtime), at(mtime)};
    return ::futimens(fd, times) == 0;
}

bool extend_at(int dir, const std::string& name, std::uint64_t old_size, Bytes data,
               std::int64_t mtime) noexcept {
    const Fd fd(::openat(dir, name.c_str(), O_WRONLY | O_NOFOLLOW | O_CLOEXEC));
    return fd.valid() && extend_undated(fd.get(), old_size, data) && set_mtime_fd(fd.get(), mtime);
}

}  // namespace fins::plc::host
#endif
