// Version 1 state files (no checksums, created in place) become version 2 files with
// their data intact: an upgrade of finsd keeps retained memory (storage_format.hpp).
#include <cstring>
#include <vector>

#include "plc/storage/storage_format.hpp"

namespace fins::plc::state_file {

namespace {

constexpr const char* file_name = "finsd.state";
constexpr const char* temp_name = "finsd.state.new";
constexpr const char* kept_name = "finsd.state.version1";

using os::last_error;

// Removes the unfinished copy unless released.
struct TempFile {
    const os::Directory& dir;
    os::Handle fd = os::none;
    ~TempFile() {
        if (fd == os::none) return;
        os::close(fd);
        os::remove(dir, temp_name);
    }
};

bool copy(os::Handle from, os::Handle to, std::uint64_t size) {
    std::vector<char> buffer(1 << 20);
    for (std::uint64_t at = 0; at < size;) {
        const auto n = os::read_at(from, buffer.data(), buffer.size(), at);
        if (n <= 0) return false;
        for (long long done = 0; done < n;) {
            const auto w =
                os::write_at(to, buffer.data() + done, static_cast<std::size_t>(n - done),
                             at + static_cast<std::uint64_t>(done));
            if (w <= 0) return false;
            done += w;
        }
        at += static_cast<std::uint64_t>(n);
    }
    return true;
}

}  // namespace

Result<os::Handle> convert_version1(const os::Directory& dir, os::Handle fd, std::uint64_t size) {
    Header h{};
    if (os::read_at(fd, &h, sizeof h, 0) != static_cast<long long>(sizeof h))
        return Unexpected(make_error(Error::not_a_state_file));
    Descriptor& d = h.descriptor;
    if (d.complete != complete_mark) return Unexpected(make_error(Error::incomplete));
    if (d.count > max_entries) return Unexpected(make_error(Error::unsupported_version));
    TempFile temp{dir};
    auto created = os::create_file(dir, temp_name);
    if (!created) return Unexpected(created.error());
    temp.fd = *created;
    if (const auto e = os::reserve(temp.fd, 0, size))
        return Unexpected(os::is_no_space(e) ? make_error(Error::no_space) : e);
    if (!copy(fd, temp.fd, size)) return Unexpected(last_error());
    // Version 1 kept 62 entries' room; version 2 uses the tail for the seal block.
    std::memset(reinterpret_cast<std::byte*>(&h) + sizeof(Descriptor), 0,
                sizeof h - sizeof(Descriptor));
    d.version = version;
    d.crc = crc_without(d, d.crc);
    h.seal.crc = crc_without(h.seal, h.seal.crc);
    if (os::write_at(temp.fd, &h, sizeof h, 0) != static_cast<long long>(sizeof h) ||
        !os::sync_data(temp.fd, {}, {nullptr, 0}))
        return Unexpected(last_error());
    // An existing finsd.state.version1 is never overwritten: the conversion stops.
    if (auto r = os::link(dir, file_name, kept_name); !r) return Unexpected(r.error());
    if (auto r = os::rename(dir, temp_name, file_name); !r) return Unexpected(r.error());
    if (auto r = os::sync(dir); !r) return Unexpected(r.error());
    const os::Handle converted = temp.fd;
    temp.fd = os::none;
    return converted;
}

}  // namespace fins::plc::state_file
