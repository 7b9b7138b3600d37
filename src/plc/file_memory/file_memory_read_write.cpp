// plc::FileMemory: 22 02 SINGLE FILE READ and 22 03 SINGLE FILE WRITE (see
// file_memory.hpp for the rules; the descriptors kept open between 22 03 chunks are in
// file_memory_open_files.cpp).
// Shared by Linux and Windows: the host calls are file_memory_os.hpp's.
#include <algorithm>

#include "plc/file_memory/file_memory.hpp"
#include "plc/file_memory/file_memory_device.hpp"
#include "plc/file_memory/file_memory_host.hpp"

namespace fins::plc {

using host::Fd;
using host::Kind;

// ---- 22 02 ----

Result<SingleFileReadResponse> FileMemory::read(const SingleFileRead& c) {
    const auto name = canonical_name(c.file);
    const auto path = parse_directory(c.directory);
    if (!name || !path || c.length > max_file_read_bytes) return fail(EndCode::parameter_error);
    auto device = open_device(c.disk);
    if (!device) return Unexpected(device.error());
    // The chunks of one transfer read through the descriptor the first one opened (see
    // write()); a file that is no longer the one the name gives takes the walk again.
    const std::string key = open_file_key(*path, *name);
    host::Info st;
    int fd = -1;
    Fd walked_fd;
    if (OpenFile* cached = find_open_file(device->index, key); cached != nullptr) {
        if (host::identity_of(cached->directory, *name, &st) == Kind::file &&
            st.inode == cached->inode && st.device == cached->host_device)
            fd = cached->fd;
        else
            close_open_file(cached);
    }
    if (fd < 0) {
        Fd dir = host::open_path(device->fd, *path);
        if (!dir.valid()) return fail(EndCode::read_file_missing);
        if (host::identity_of(dir.get(), *name, &st) != Kind::file)
            return fail(EndCode::read_file_missing);
        if (OpenFile* kept = keep_open(device->index, key, dir.get(), *name); kept != nullptr) {
            static_cast<void>(dir.release());
            fd = kept->fd;
        } else {
            walked_fd = Fd(host::open_file(dir.get(), *name, host::Access::read));
            if (!walked_fd.valid() || !host::stat(walked_fd.get(), st))
                return fail(EndCode::read_file_missing);
            fd = walked_fd.get();
        }
    }
    const auto size = st.size;
    if (c.position > size) return fail(EndCode::address_range_error);
    const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(c.length, size - c.position));
    SingleFileReadResponse r;
    r.file_size = static_cast<std::uint32_t>(std::min<std::uint64_t>(size, 0xFFFFFFFF));
    r.position = c.position;
    r.data.resize(n);
    std::size_t done = 0;
    if (!host::read_fully(fd, r.data.data(), n, c.position, done) || done != n)
        return fail(EndCode::memory_error);
    r.last = c.position + n == size;
    return r;
}

// ---- 22 03 ----

EndCode FileMemory::write(const SingleFileWrite& c, CivilSeconds now) {
    const auto name = canonical_name(c.file);
    const auto path = parse_directory(c.directory);
    if (!name || !path || c.mode > static_cast<std::uint16_t>(FileWriteMode::overwrite))
        return EndCode::parameter_error;
    const auto mode = static_cast<FileWriteMode>(c.mode);
    // 5-3-34: "To create a new file or add data to an existing file, specify 00000000".
    if (mode != FileWriteMode::overwrite && c.position != 0) return EndCode::parameter_error;
    auto device = open_device(c.disk);
    if (!device) return EndCode{static_cast<std::uint16_t>(device.error().value())};
    close_idle_files(now);
    // The chunks of one transfer: the directory and file stay open while the name still
    // names the same regular file (no walk, no open); anything else takes the walk.
    const std::string key = open_file_key(*path, *name);
    host::Info st;
    auto kind = Kind::missing;
    int dir_fd = -1;
    Fd walked;
    OpenFile* cached = find_open_file(device->index, key);
    if (cached != nullptr) {
        kind = host::identity_of(cached->directory, *name, &st);
        if (kind == Kind::file && st.inode == cached->inode && st.device == cached->host_device) {
            dir_fd = cached->directory;
        } else {
            close_open_file(cached);
            cached = nullptr;
        }
    }
    if (dir_fd < 0) {
        walked = host::open_path(device->fd, *path);
        if (!walked.valid()) return EndCode::write_file_missing;
        dir_fd = walked.get();
        kind = host::kind_of(dir_fd, *name, &st);
    }
    if (kind != Kind::missing && kind != Kind::file) return EndCode::file_name_exists;
    const bool exists = kind == Kind::file;
    const std::uint64_t old_size = exists ? st.size : 0;

    std::uint64_t offset = 0;
    switch (mode) {
        case FileWriteMode::create:
            if (exists) return EndCode::file_name_exists;
            break;
        case FileWriteMode::create_or_replace:
            break;
        case FileWriteMode::append:
            if (!exists) return EndCode::write_file_missing;
            offset = old_size;
            break;
        case FileWriteMode::overwrite:
            if (!exists) return EndCode::write_file_missing;
            if (c.position > old_size) return EndCode::address_range_error;
            offset = c.position;
            break;
    }
    const bool replacing =
        mode == FileWriteMode::create || mode == FileWriteMode::create_or_replace;
    const std::uint64_t end = offset + c.data.size();
    if (end > 0xFFFFFFFF) return EndCode::address_range_exceeded;
    const std::uint64_t new_size = replacing ? c.data.size() : std::max(old_size, end);
    const auto used = bytes_in_use(*device);
    if (new_size > old_size && used + (new_size - old_size) > device->capacity)
        return EndCode::address_range_exceeded;

    bool ok = false;
    if (offset == old_size && !replacing) {
        // Only adds bytes: nothing already in the file can be half-changed.
        if (cached == nullptr && walked.valid()) {
            cached = keep_open(device->index, key, walked.get(), *name);
            if (cached != nullptr) static_cast<void>(walked.release());
        }
        if (cached != nullptr) {
            ok = host::extend_undated(cached->fd, offset, c.data);
            if (ok) {
                cached->last_write = now;
                cached->undated = true;
            }
        } else {
            ok = host::extend_at(dir_fd, *name, offset, c.data, now);
        }
    } else {
        // A new inode replaces the file: the kept descriptor would write to the old one.
        if (cached != nullptr) close_open_file(cached);
        if (!walked.valid()) {
            walked = host::open_path(device->fd, *path);
            if (!walked.valid()) return EndCode::write_file_missing;
        }
        if (replacing) {
            ok = host::replace(walked.get(), *name, c.data, now, temp_counter_);
        } else {
            auto content = host::read_all(walked.get(), *name);
            if (!content) return EndCode::memory_error;
            content->resize(static_cast<std::size_t>(new_size));
            std::copy(c.data.begin(), c.data.end(),
                      content->begin() + static_cast<std::ptrdiff_t>(offset));
            ok = host::replace(walked.get(), *name, *content, now, temp_counter_);
        }
    }
    if (!ok) return EndCode::memory_error;
    used_[device->index] = (used >= old_size ? used - old_size : 0) + new_size;
    return EndCode::normal_completion;
}

}  // namespace fins::plc
