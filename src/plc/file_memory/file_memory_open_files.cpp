// plc::FileMemory: descriptors kept open between the chunks of one 22 03 transfer (see
// FileMemory::OpenFile in file_memory.hpp).
// Shared by Linux and Windows: the host calls are file_memory_os.hpp's.
#include <algorithm>

#include "plc/file_memory/file_memory.hpp"
#include "plc/file_memory/file_memory_host.hpp"

namespace fins::plc {

std::string FileMemory::open_file_key(const std::vector<std::string>& path,
                                      const std::string& name) {
    std::string key;
    for (const auto& component : path)
        key += "\\" + component;
    key += "\\" + name;
    return key;
}

FileMemory::OpenFile* FileMemory::find_open_file(std::size_t device,
                                                 const std::string& key) noexcept {
    for (auto& f : open_files_)
        if (f.device == device && f.key == key) {
            f.last_use = ++use_counter_;
            return &f;
        }
    return nullptr;
}

FileMemory::OpenFile* FileMemory::keep_open(std::size_t device, std::string key, int directory,
                                            const std::string& name) {
    // Read and write: 22 02 chunks read through it, 22 03 chunks extend it.
    const int fd = host::open_file(directory, name, host::Access::read_write);
    host::Info st;
    if (fd < 0 || !host::stat(fd, st)) {
        host::close(fd);
        return nullptr;
    }
    if (open_files_.size() >= max_open_files) {
        const auto oldest = std::min_element(
            open_files_.begin(), open_files_.end(),
            [](const OpenFile& a, const OpenFile& b) { return a.last_use < b.last_use; });
        close_open_file(&*oldest);
    }
    OpenFile f;
    f.device = device;
    f.key = std::move(key);
    f.directory = directory;
    f.fd = fd;
    f.host_device = st.device;
    f.inode = st.inode;
    f.last_use = ++use_counter_;
    open_files_.push_back(std::move(f));
    return &open_files_.back();
}

void FileMemory::close_open_file(OpenFile* file) noexcept {
    if (file->undated) host::set_mtime(file->fd, file->last_write);
    host::close(file->fd);
    host::close(file->directory);
    const auto index = static_cast<std::ptrdiff_t>(file - open_files_.data());
    open_files_.erase(open_files_.begin() + index);
}

void FileMemory::forget_open_files(std::optional<std::size_t> device) noexcept {
    for (std::size_t i = open_files_.size(); i-- > 0;)
        if (!device || open_files_[i].device == *device) close_open_file(&open_files_[i]);
}

void FileMemory::date_open_files() noexcept {
    for (auto& f : open_files_)
        if (f.undated) {
            host::set_mtime(f.fd, f.last_write);
            f.undated = false;
        }
}

void FileMemory::close_idle_files(CivilSeconds now) noexcept {
    for (std::size_t i = open_files_.size(); i-- > 0;) {
        const auto idle = now - open_files_[i].last_write;
        if (idle > open_file_idle_seconds || idle < -open_file_idle_seconds)
            close_open_file(&open_files_[i]);
    }
}

}  // namespace fins::plc
