// plc::FileMemory: the 22 xx file devices (see file_memory.hpp for the rules).
// Shared by Linux and Windows: the host calls are file_memory_os.hpp's.
#include "plc/file_memory/file_memory.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <ctime>

#include "plc/file_memory/file_memory_device.hpp"
#include "plc/file_memory/file_memory_host.hpp"

namespace fins::plc {

using host::Fd;
using host::Kind;

namespace {

constexpr std::uint32_t card_volume_date_fallback = 0;

std::uint32_t date_of(std::int64_t mtime) noexcept {
    const auto t = static_cast<std::time_t>(mtime);
    std::tm tm{};
    if (::gmtime_r(&t, &tm) == nullptr) return card_volume_date_fallback;
    return pack_file_date(tm.tm_year + 1900, static_cast<unsigned>(tm.tm_mon + 1),
                          static_cast<unsigned>(tm.tm_mday), static_cast<unsigned>(tm.tm_hour),
                          static_cast<unsigned>(tm.tm_min), static_cast<unsigned>(tm.tm_sec));
}

FileEntry entry_of(const std::string& name, const host::Info& info, bool directory) {
    FileEntry e;
    e.name = *FileName::from(name);
    e.date = date_of(info.mtime);
    e.size = directory ? 0 : static_cast<std::uint32_t>(info.size);
    e.attribute = directory ? attribute_directory : attribute_archive;
    return e;
}

FileEntry dot_entry(std::string_view dots, const host::Info& info) {
    FileEntry e;
    e.name.bytes.fill(0x20);
    for (std::size_t i = 0; i < dots.size(); ++i)
        e.name.bytes[i] = '.';
    e.date = date_of(info.mtime);
    e.attribute = attribute_directory;
    return e;
}

const std::string volume_file = ".volume";

// The volume label's date lives in the mtime of an empty hidden file, made with the
// device directory (22 04 dates it again).
void date_volume(int device, CivilSeconds date) noexcept {
    bool exists = false;
    const Fd v(host::create_file(device, volume_file, exists));
    host::set_mtime_at(device, volume_file, date);
}

void ensure_volume(int device) noexcept {
    if (host::kind_of(device, volume_file) != Kind::missing) return;
    date_volume(device, Clock::host_local(std::chrono::system_clock::now()));
}

}  // namespace

// ---- devices ----

FileMemory::FileMemory(const Profile& profile)
    : profile_(profile),
      card_kbytes_(profile.memory_card_kbytes),
      cassette_mounted_(profile.memory_cassette) {
    if (profile.em_file_bank < profile.em_banks) em_bank_ = profile.em_file_bank;
}

FileMemory::~FileMemory() {
    close_devices();
    host::close(root_fd_);
    if (own_root_) {
        std::error_code ec;
        std::filesystem::remove_all(root_, ec);
    }
}

void FileMemory::set_em_file_bank(std::optional<std::uint8_t> bank) noexcept {
    forget_open_files(1);
    em_bank_ = bank && *bank < profile_.em_banks ? bank : std::nullopt;
}

std::uint8_t FileMemory::em_non_file_banks() const noexcept {
    return em_bank_ ? *em_bank_ : profile_.em_banks;
}

Result<void> FileMemory::attach(const std::filesystem::path& root) {
    std::error_code ec;
    std::filesystem::create_directories(root, ec);
    std::error_code error;
    Fd fd(host::open_root(root, error));
    if (!fd.valid()) return Unexpected(error);
    // Device directories that are links: opened now, following that one link.
    constexpr std::array<const char*, 3> devices = {"card", "em", "cassette"};
    std::array<Fd, 3> linked;
    std::vector<DeviceLink> links;
    std::error_code refused;
    for (std::size_t i = 0; i < devices.size(); ++i) {
        if (!host::is_link(fd.get(), devices[i])) continue;
        DeviceLink link{devices[i], std::filesystem::read_symlink(root / devices[i], ec), {}};
        linked[i] = Fd(host::open_linked_directory(fd.get(), devices[i], link.error));
        if (!linked[i].valid() && !refused) refused = link.error;
        links.push_back(std::move(link));
    }
    device_links_ = std::move(links);
    if (refused) return Unexpected(refused);
    close_devices();
    host::close(root_fd_);
    if (own_root_) std::filesystem::remove_all(root_, ec);
    root_fd_ = fd.release();
    root_ = root;
    own_root_ = false;
    device_fds_[0] = linked[0].release();
    device_fds_[1] = linked[1].release();
    cassette_fd_ = linked[2].release();
    for (std::size_t i = 0; i < devices.size(); ++i) {
        const int kept = i == 2 ? cassette_fd_ : device_fds_[i];
        if (kept >= 0) {
            host::clear(kept, true);
            if (i < 2) ensure_volume(kept);
        } else if (const Fd dir(host::open_directory(root_fd_, devices[i])); dir.valid()) {
            host::clear(dir.get(), true);
        }
    }
    return {};
}

Result<void> FileMemory::ensure_root() {
    if (root_fd_ >= 0) return {};
    std::error_code error;
    const auto dir = host::make_temp_directory(error);
    if (error) return Unexpected(error);
    if (auto r = attach(dir); !r) return r;
    own_root_ = true;
    return {};
}

Result<FileMemory::Device> FileMemory::open_device(std::uint16_t disk) {
    Device d;
    const char* dir = nullptr;
    if (disk == disk_memory_card) {
        if (!card_inserted()) return fail(EndCode::file_device_missing);
        dir = "card";
        d.index = 0;
        d.capacity = std::uint64_t{card_kbytes_} * 1024;
        d.label = "MEMCARD";
    } else if (disk == disk_em_file) {
        if (!em_bank_) return fail(EndCode::file_device_missing);
        dir = "em";
        d.index = 1;
        d.capacity = static_cast<std::uint64_t>(profile_.em_banks - *em_bank_) * em_bank_bytes;
        d.label = "EMFILE";
    } else {
        return fail(EndCode::parameter_error);
    }
    if (!ensure_root()) return fail(EndCode::memory_error);
    // The device directory stays open: one openat per request less, and the bytes in use
    // are counted once and then tracked (used()).
    int& fd = device_fds_[d.index];
    if (fd < 0) {
        if (host::make_directory(root_fd_, dir) == host::Status::failed)
            return fail(EndCode::memory_error);
        fd = host::open_directory(root_fd_, dir);
        if (fd < 0) return fail(EndCode::memory_error);
        used_[d.index].reset();
        ensure_volume(fd);
    }
    d.fd = fd;
    return d;
}

void FileMemory::close_devices() noexcept {
    forget_open_files();
    for (std::size_t i = 0; i < 2; ++i) {
        host::close(device_fds_[i]);
        device_fds_[i] = -1;
        used_[i].reset();
    }
    host::close(cassette_fd_);
    cassette_fd_ = -1;
}

std::uint64_t FileMemory::bytes_in_use(const Device& d) {
    auto& used = used_[d.index];
    if (!used) used = host::used_bytes(d.fd);
    return *used;
}

// ---- 22 01 ----

Result<FileNameReadResponse> FileMemory::list(const FileNameRead& c) {
    if (c.count > max_file_entries) return fail(EndCode::parameter_error);
    const auto path = parse_directory(c.directory);
    if (!path) return fail(EndCode::parameter_error);
    auto device = open_device(c.disk);
    if (!device) return Unexpected(device.error());
    date_open_files();
    const Fd dir = host::open_path(device->fd, *path);
    if (!dir.valid()) return fail(EndCode::read_file_missing);

    host::Info volume;
    const bool dated = host::kind_of(device->fd, volume_file, &volume) != Kind::missing;
    std::vector<FileEntry> all;
    if (path->empty()) {
        // 5-3-32 "Total Number of Files": "Volume labels ... are all counted as files. (The
        // root directory can contain a volume label, but not a current directory or parent
        // directory mark.)" On FAT the label is an entry of the root directory, first here:
        // attribute 08 (volume label), size 0, the date of the label (the last format).
        FileEntry label;
        label.name = *FileName::from(device->label);
        label.date = dated ? date_of(volume.mtime) : 0;
        label.attribute = attribute_volume;
        all.push_back(label);
    } else {
        host::Info info;
        host::stat(dir.get(), info);
        all.push_back(dot_entry(".", info));
        all.push_back(dot_entry("..", info));
    }
    for (const auto& e :
         host::entries(dir.get(), [](std::string_view n) { return FileMemory::visible(n); }))
        all.push_back(entry_of(e.name, e.info, e.kind == Kind::directory));

    FileNameReadResponse r;
    r.disk.volume_label = *FileName::from(device->label);
    if (dated) r.disk.date = date_of(volume.mtime);
    const auto used = bytes_in_use(*device);
    r.disk.total_capacity =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(device->capacity, 0xFFFFFFFF));
    r.disk.free_capacity = static_cast<std::uint32_t>(
        std::min<std::uint64_t>(device->capacity - std::min(used, device->capacity), 0xFFFFFFFF));
    r.disk.total_files = static_cast<std::uint16_t>(std::min<std::size_t>(all.size(), 0x7FFF));
    const std::size_t first = std::min<std::size_t>(c.first, all.size());
    const std::size_t end = std::min<std::size_t>(first + c.count, all.size());
    r.files.assign(all.begin() + static_cast<std::ptrdiff_t>(first),
                   all.begin() + static_cast<std::ptrdiff_t>(end));
    r.last = end == all.size() && c.count != 0;
    return r;
}

// ---- 22 04 ----

EndCode FileMemory::format(std::uint16_t disk, std::uint8_t current_em_bank, CivilSeconds now) {
    if (disk == disk_em_file && em_bank_ && current_em_bank >= *em_bank_ && current_em_bank != 0)
        return EndCode::area_classification_missing;
    auto device = open_device(disk);
    if (!device) return EndCode{static_cast<std::uint16_t>(device.error().value())};
    forget_open_files(device->index);
    used_[device->index].reset();
    if (!host::clear(device->fd, false)) return EndCode::memory_error;
    date_volume(device->fd, now);
    return EndCode::normal_completion;
}

// ---- 22 05 ----

Result<std::uint16_t> FileMemory::remove(const FileDelete& c) {
    const auto path = parse_directory(c.directory);
    if (!path) return fail(EndCode::parameter_error);
    std::vector<std::string> names;
    for (const auto& f : c.files) {
        auto name = canonical_name(f);
        if (!name) return fail(EndCode::parameter_error);
        names.push_back(std::move(*name));
    }
    auto device = open_device(c.disk);
    if (!device) return Unexpected(device.error());
    const Fd dir = host::open_path(device->fd, *path);
    if (!dir.valid()) return fail(EndCode::write_file_missing);
    forget_open_files(device->index);
    used_[device->index].reset();
    std::uint16_t deleted = 0;
    // 5-3-36: names that do not exist are ignored; so are directories (22 15 removes those).
    for (const auto& name : names)
        if (host::kind_of(dir.get(), name) == Kind::file &&
            host::remove(dir.get(), name, false) == host::Status::ok)
            ++deleted;
    return deleted;
}

// ---- 22 07 ----

EndCode FileMemory::copy(const FileCopy& c) {
    const auto from = canonical_name(c.source);
    const auto to = canonical_name(c.destination);
    const auto from_path = parse_directory(c.source_directory);
    const auto to_path = parse_directory(c.destination_directory);
    if (!from || !to || !from_path || !to_path) return EndCode::parameter_error;
    auto source = open_device(c.source_disk);
    if (!source) return EndCode{static_cast<std::uint16_t>(source.error().value())};
    auto target = open_device(c.destination_disk);
    if (!target) return EndCode{static_cast<std::uint16_t>(target.error().value())};
    forget_open_files(target->index);
    date_open_files();  // the copy takes the source's date
    const Fd from_dir = host::open_path(source->fd, *from_path);
    host::Info st;
    if (!from_dir.valid() || host::kind_of(from_dir.get(), *from, &st) != Kind::file)
        return EndCode::read_file_missing;
    const Fd to_dir = host::open_path(target->fd, *to_path);
    if (!to_dir.valid()) return EndCode::write_file_missing;
    if (host::kind_of(to_dir.get(), *to) != Kind::missing) return EndCode::file_name_exists;
    const auto content = host::read_all(from_dir.get(), *from);
    if (!content) return EndCode::memory_error;
    const auto used = bytes_in_use(*target);
    if (used + content->size() > target->capacity) return EndCode::address_range_exceeded;
    // 5-3-37: "The copy destination file is given the same date as the copy source file."
    if (!host::replace(to_dir.get(), *to, *content, st.mtime, temp_counter_))
        return EndCode::memory_error;
    used_[target->index] = used + content->size();
    return EndCode::normal_completion;
}

// ---- 22 08 ----

EndCode FileMemory::rename(const FileNameChange& c) {
    const auto from = canonical_name(c.old_name);
    const auto to = canonical_name(c.new_name);
    const auto path = parse_directory(c.directory);
    if (!from || !to || !path) return EndCode::parameter_error;
    auto device = open_device(c.disk);
    if (!device) return EndCode{static_cast<std::uint16_t>(device.error().value())};
    forget_open_files(device->index);
    const Fd dir = host::open_path(device->fd, *path);
    if (!dir.valid()) return EndCode::write_file_missing;
    const auto kind = host::kind_of(dir.get(), *from);
    if (kind != Kind::file && kind != Kind::directory) return EndCode::write_file_missing;
    if (*from == *to) return EndCode::file_name_exists;
    if (host::kind_of(dir.get(), *to) != Kind::missing) return EndCode::file_name_exists;
    // A rename keeps the date (5-3-38 "the date of the file will remain unchanged").
    if (!host::rename(dir.get(), *from, *to)) return EndCode::memory_error;
    host::sync(dir.get());
    return EndCode::normal_completion;
}

// ---- 22 15 ----

EndCode FileMemory::directory(const DirectoryCreateDelete& c, CivilSeconds now) {
    const auto name = canonical_name(c.directory_name);
    const auto path = parse_directory(c.parent);
    if (!name || !path || c.operation > static_cast<std::uint16_t>(DirectoryOperation::remove))
        return EndCode::parameter_error;
    auto device = open_device(c.disk);
    if (!device) return EndCode{static_cast<std::uint16_t>(device.error().value())};
    forget_open_files(device->index);
    const Fd dir = host::open_path(device->fd, *path);
    if (!dir.valid()) return EndCode::write_file_missing;
    const auto kind = host::kind_of(dir.get(), *name);
    if (c.operation == static_cast<std::uint16_t>(DirectoryOperation::create)) {
        if (kind != Kind::missing) return EndCode::file_name_exists;
        if (path->size() >= max_file_directories) return EndCode::cannot_register;
        if (host::make_directory(dir.get(), *name) != host::Status::ok)
            return EndCode::memory_error;
        host::set_mtime_at(dir.get(), *name, now);
        host::sync(dir.get());
        return EndCode::normal_completion;
    }
    if (kind != Kind::directory) return EndCode::write_file_missing;
    switch (host::remove(dir.get(), *name, true)) {
        case host::Status::ok:
            return EndCode::normal_completion;
        case host::Status::not_empty:
            return EndCode::cannot_change;
        default:
            return EndCode::memory_error;
    }
}

// ---- whole files for 22 0A .. 22 0C ----

Result<std::vector<std::uint8_t>> FileMemory::load(std::uint16_t disk, const FileName& file,
                                                   const std::string& directory) {
    const auto name = canonical_name(file);
    const auto path = parse_directory(directory);
    if (!name || !path) return fail(EndCode::parameter_error);
    auto device = open_device(disk);
    if (!device) return Unexpected(device.error());
    const Fd dir = host::open_path(device->fd, *path);
    if (!dir.valid()) return fail(EndCode::read_file_missing);
    auto content = host::read_all(dir.get(), *name);
    if (!content) return fail(EndCode::read_file_missing);
    return std::move(*content);
}

EndCode FileMemory::create(std::uint16_t disk, const FileName& file, const std::string& directory,
                           Bytes content, CivilSeconds now) {
    const auto name = canonical_name(file);
    const auto path = parse_directory(directory);
    if (!name || !path) return EndCode::parameter_error;
    auto device = open_device(disk);
    if (!device) return EndCode{static_cast<std::uint16_t>(device.error().value())};
    forget_open_files(device->index);
    const Fd dir = host::open_path(device->fd, *path);
    if (!dir.valid()) return EndCode::write_file_missing;
    if (host::kind_of(dir.get(), *name) != Kind::missing) return EndCode::file_name_exists;
    const auto used = bytes_in_use(*device);
    if (used + content.size() > device->capacity) return EndCode::address_range_exceeded;
    if (!host::replace(dir.get(), *name, content, now, temp_counter_)) return EndCode::memory_error;
    used_[device->index] = used + content.size();
    return EndCode::normal_completion;
}

}  // namespace fins::plc
