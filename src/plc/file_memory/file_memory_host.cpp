// Host file-system helpers of plc::FileMemory (see file_memory_host.hpp): shared by
// Linux and Windows, on the calls of file_memory_os.hpp.
#include "plc/file_memory/file_memory_host.hpp"

#include <algorithm>
#include <string>

namespace fins::plc::host {

namespace {

constexpr int max_depth = 16;  // host trees deeper than FINS allows are not walked further
constexpr std::string_view temp_prefix = ".tmp-";

bool write_fully(int fd, Bytes data, std::uint64_t offset) noexcept {
    std::size_t done = 0;
    while (done < data.size()) {
        const auto n = write_at(fd, data.data() + done, data.size() - done, offset + done);
        if (n <= 0) return false;
        done += static_cast<std::size_t>(n);
    }
    return true;
}

bool any(std::string_view name) {
    return !name.empty();
}

}  // namespace

Kind kind_of(int dir, const std::string& name, Info* info) noexcept {
    return stat_at(dir, name, info, true);
}

Kind identity_of(int dir, const std::string& name, Info* info) noexcept {
    return stat_at(dir, name, info, false);
}

Fd open_path(int dir, const std::vector<std::string>& components) noexcept {
    Fd current(duplicate(dir));
    for (const auto& c : components) {
        if (!current.valid()) return current;
        current = Fd(open_directory(current.get(), c));
    }
    return current;
}

std::vector<Entry> entries(int dir, bool (*visible)(std::string_view name)) {
    std::vector<Entry> out;
    for (auto& name : names(dir)) {
        if (!visible(name)) continue;
        Entry entry;
        entry.name = std::move(name);
        entry.kind = kind_of(dir, entry.name, &entry.info);
        if (entry.kind == Kind::file || entry.kind == Kind::directory)
            out.push_back(std::move(entry));
    }
    std::sort(out.begin(), out.end(),
              [](const Entry& a, const Entry& b) { return a.name < b.name; });
    return out;
}

std::uint64_t used_bytes(int dir, int depth) noexcept {
    if (depth > max_depth) return 0;
    std::uint64_t total = 0;
    try {
        for (const auto& e : entries(dir, any)) {
            if (e.kind == Kind::file) {
                total += e.info.size;
            } else if (e.kind == Kind::directory) {
                const Fd sub(open_directory(dir, e.name));
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
        for (const auto& e : entries(dir, any)) {
            const bool temp = e.name.starts_with(temp_prefix);
            if (e.kind == Kind::directory) {
                {  // closed before its removal: Windows removes no directory held open
                    const Fd sub(open_directory(dir, e.name));
                    if (sub.valid()) ok = clear(sub.get(), only_temps, depth + 1) && ok;
                }
                if (!only_temps && remove(dir, e.name, true) != Status::ok) ok = false;
            } else if (!only_temps || temp) {
                if (remove(dir, e.name, false) != Status::ok) ok = false;
            }
        }
    } catch (...) {
        return false;
    }
    return ok;
}

bool read_fully(int fd, std::uint8_t* data, std::size_t size, std::uint64_t offset,
                std::size_t& done) noexcept {
    done = 0;
    while (done < size) {
        const auto n = read_at(fd, data + done, size - done, offset + done);
        if (n < 0) return false;
        if (n == 0) break;
        done += static_cast<std::size_t>(n);
    }
    return true;
}

std::optional<std::vector<std::uint8_t>> read_all(int dir, const std::string& name) {
    const Fd fd(open_file(dir, name, Access::read));
    Info info;
    if (!fd.valid() || !stat(fd.get(), info)) return std::nullopt;
    std::vector<std::uint8_t> out(static_cast<std::size_t>(info.size));
    std::size_t done = 0;
    if (!read_fully(fd.get(), out.data(), out.size(), 0, done)) return std::nullopt;
    out.resize(done);
    return out;
}

bool replace(int dir, const std::string& name, Bytes content, std::int64_t mtime,
             unsigned& counter) noexcept {
    std::string temp;
    Fd fd;
    for (int attempt = 0; attempt < 100 && !fd.valid(); ++attempt) {
        temp = std::string(temp_prefix) + std::to_string(process_id()) + "-" +
               std::to_string(counter++);
        bool exists = false;
        fd = Fd(create_file(dir, temp, exists));
        if (!fd.valid() && !exists) return false;
    }
    if (!fd.valid()) return false;
    const bool ok =
        write_fully(fd.get(), content, 0) && sync(fd.get()) && set_mtime(fd.get(), mtime);
    fd = Fd();  // closed before the rename: Windows renames no file open without sharing
    if (!ok || !rename(dir, temp, name)) {
        remove(dir, temp, false);
        return false;
    }
    sync(dir);
    return true;
}

bool extend_undated(int fd, std::uint64_t old_size, Bytes data) noexcept {
    if (write_fully(fd, data, old_size)) return true;
    // The bytes that fitted before the host refused the rest would make the file larger
    // than any acknowledged write: a client resuming at 22 02's size would skip data.
    truncate(fd, old_size);
    return false;
}

bool extend_at(int dir, const std::string& name, std::uint64_t old_size, Bytes data,
               std::int64_t mtime) noexcept {
    const Fd fd(open_file(dir, name, Access::write));
    return fd.valid() && extend_undated(fd.get(), old_size, data) && set_mtime(fd.get(), mtime);
}

}  // namespace fins::plc::host
