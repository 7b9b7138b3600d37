// Version 1 state files (no checksums, created in place) become version 2 files with
// their data intact: an upgrade of finsd keeps retained memory (storage_format.hpp).
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "plc/storage_format.hpp"

namespace fins::plc::state_file {

namespace {

constexpr const char* file_name = "finsd.state";
constexpr const char* temp_name = "finsd.state.new";
constexpr const char* kept_name = "finsd.state.version1";

std::error_code last_error() {
    return {errno, std::system_category()};
}

// Removes the unfinished copy unless released.
struct TempFile {
    int dir_fd;
    int fd = -1;
    ~TempFile() {
        if (fd < 0) return;
        ::close(fd);
        ::unlinkat(dir_fd, temp_name, 0);
    }
};

bool copy(int from, int to, std::uint64_t size) {
    std::vector<char> buffer(1 << 20);
    for (std::uint64_t at = 0; at < size;) {
        const auto n = ::pread(from, buffer.data(), buffer.size(), static_cast<off_t>(at));
        if (n <= 0) return false;
        for (ssize_t done = 0; done < n;) {
            const auto w = ::pwrite(to, buffer.data() + done, static_cast<std::size_t>(n - done),
                                    static_cast<off_t>(at) + done);
            if (w <= 0) return false;
            done += w;
        }
        at += static_cast<std::uint64_t>(n);
    }
    return true;
}

}  // namespace

Result<int> convert_version1(int dir_fd, int fd, std::uint64_t size) {
    Header h{};
    if (::pread(fd, &h, sizeof h, 0) != static_cast<ssize_t>(sizeof h))
        return Unexpected(make_error(Error::not_a_state_file));
    Descriptor& d = h.descriptor;
    if (d.complete != complete_mark) return Unexpected(make_error(Error::incomplete));
    if (d.count > max_entries) return Unexpected(make_error(Error::unsupported_version));
    TempFile temp{dir_fd};
    temp.fd = ::openat(dir_fd, temp_name, O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (temp.fd < 0) return Unexpected(last_error());
    if (const int e = ::posix_fallocate(temp.fd, 0, static_cast<off_t>(size)); e != 0)
        return Unexpected(e == ENOSPC || e == EDQUOT || e == EFBIG
                              ? make_error(Error::no_space)
                              : std::error_code(e, std::system_category()));
    if (!copy(fd, temp.fd, size)) return Unexpected(last_error());
    // Version 1 kept 62 entries' room; version 2 uses the tail for the seal block.
    std::memset(reinterpret_cast<std::byte*>(&h) + sizeof(Descriptor), 0,
                sizeof h - sizeof(Descriptor));
    d.version = version;
    d.crc = crc_without(d, d.crc);
    h.seal.crc = crc_without(h.seal, h.seal.crc);
    if (::pwrite(temp.fd, &h, sizeof h, 0) != static_cast<ssize_t>(sizeof h) ||
        ::fdatasync(temp.fd) != 0)
        return Unexpected(last_error());
    // An existing finsd.state.version1 is never overwritten: the conversion stops.
    if (::linkat(dir_fd, file_name, dir_fd, kept_name, 0) != 0) return Unexpected(last_error());
    if (::renameat(dir_fd, temp_name, dir_fd, file_name) != 0 || ::fsync(dir_fd) != 0)
        return Unexpected(last_error());
    const int converted = temp.fd;
    temp.fd = -1;
    return converted;
}

}  // namespace fins::plc::state_file
