#include "plc/storage.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <vector>

namespace fins::plc {

namespace {

// The state file: one header page, then each retained section on its own page-aligned
// run, in the order the models asked for them.
constexpr std::array<char, 8> file_magic{'F', 'I', 'N', 'S', 'K', 'I', 'T', '\0'};
constexpr std::uint32_t file_version = 1;
constexpr std::size_t page = 4096;
constexpr std::size_t name_size = 40;
constexpr std::size_t profile_size = 64;

struct FileEntry {
    char name[name_size];
    std::uint64_t offset;
    std::uint64_t size;
    std::uint64_t reserved;
};

struct FileHeader {
    std::array<char, 8> magic;
    std::uint32_t version;
    std::uint32_t complete;  // set by seal(): every section of the profile is present
    char profile[profile_size];
    std::uint64_t file_size;
    std::uint32_t count;
    std::uint32_t reserved;
    FileEntry entries[(page - 96) / sizeof(FileEntry)];
};
static_assert(sizeof(FileHeader) <= page);
constexpr std::size_t max_entries = sizeof(FileHeader::entries) / sizeof(FileEntry);

enum class StorageError : int {
    not_a_state_file = 1,
    unsupported_version,
    other_profile,
    damaged,
    layout_mismatch,
    in_use,
    too_many_sections,
    duplicate_section,
    profile_id_too_long,
};

class StorageCategory final : public std::error_category {
  public:
    const char* name() const noexcept override { return "fins.storage"; }
    std::string message(int c) const override {
        switch (static_cast<StorageError>(c)) {
            case StorageError::not_a_state_file:
                return "not a finsd state file";
            case StorageError::unsupported_version:
                return "state file written by an unsupported finsd format version";
            case StorageError::other_profile:
                return "state file belongs to another PLC profile (use another --data-dir)";
            case StorageError::damaged:
                return "state file is damaged (size or section table)";
            case StorageError::layout_mismatch:
                return "state file sections do not match this profile's memory layout";
            case StorageError::in_use:
                return "state file is in use by another finsd";
            case StorageError::too_many_sections:
                return "too many retained sections";
            case StorageError::duplicate_section:
                return "two retained sections of the same name";
            case StorageError::profile_id_too_long:
                return "profile id too long for a state file";
        }
        return "storage error";
    }
};

const StorageCategory storage_category_instance;

std::error_code make(StorageError e) {
    return {static_cast<int>(e), storage_category_instance};
}

std::size_t round_up(std::size_t n) {
    return (n + page - 1) / page * page;
}

}  // namespace

struct Storage::Impl {
    // Heap sections, 8-byte aligned (enough for every stored type).
    std::vector<std::vector<std::uint64_t>> heap;
    int fd = -1;
    FileHeader* header = nullptr;
    std::vector<std::pair<void*, std::size_t>> maps;
    std::vector<bool> claimed;  // per existing entry
    bool existing = false;
    std::error_code problem;
    std::filesystem::path path;

    std::span<std::byte> on_heap(std::size_t bytes) {
        heap.emplace_back((bytes + 7) / 8 + 1, 0);
        return {reinterpret_cast<std::byte*>(heap.back().data()), bytes};
    }

    std::span<std::byte> map(std::uint64_t offset, std::size_t bytes) {
        const std::size_t length = round_up(std::max<std::size_t>(bytes, 1));
        void* p = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd,
                         static_cast<off_t>(offset));
        if (p == MAP_FAILED) {
            problem = std::error_code(errno, std::system_category());
            return on_heap(bytes);
        }
        maps.emplace_back(p, length);
        return {static_cast<std::byte*>(p), bytes};
    }

    ~Impl() {
        for (auto [p, n] : maps)
            ::munmap(p, n);
        if (header) ::munmap(header, page);
        if (fd >= 0) ::close(fd);
    }
};

Storage::Storage() : impl_(std::make_unique<Impl>()) {}
Storage::Storage(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Storage::~Storage() = default;

Result<std::unique_ptr<Storage>> Storage::open(const std::filesystem::path& dir,
                                               std::string_view profile_id) {
    // The header keeps the id NUL-terminated; a longer one could never match again.
    if (profile_id.size() >= profile_size)
        return Unexpected(make(StorageError::profile_id_too_long));
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) return Unexpected(ec);
    auto impl = std::make_unique<Impl>();
    impl->path = dir / "finsd.state";
    impl->fd = ::open(impl->path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (impl->fd < 0) return Unexpected(std::error_code(errno, std::system_category()));
    if (::flock(impl->fd, LOCK_EX | LOCK_NB) != 0) return Unexpected(make(StorageError::in_use));

    struct stat st {};
    if (::fstat(impl->fd, &st) != 0)
        return Unexpected(std::error_code(errno, std::system_category()));
    const auto size = static_cast<std::uint64_t>(st.st_size);
    if (size > 0 && size < page) return Unexpected(make(StorageError::not_a_state_file));
    if (size == 0 && ::ftruncate(impl->fd, page) != 0)
        return Unexpected(std::error_code(errno, std::system_category()));
    void* h = ::mmap(nullptr, page, PROT_READ | PROT_WRITE, MAP_SHARED, impl->fd, 0);
    if (h == MAP_FAILED) return Unexpected(std::error_code(errno, std::system_category()));
    impl->header = static_cast<FileHeader*>(h);
    FileHeader& hd = *impl->header;

    const bool fresh = size == 0 || (hd.magic == file_magic && hd.complete == 0);
    if (!fresh) {
        if (hd.magic != file_magic) return Unexpected(make(StorageError::not_a_state_file));
        if (hd.version != file_version) return Unexpected(make(StorageError::unsupported_version));
        if (std::string_view(hd.profile, ::strnlen(hd.profile, profile_size)) != profile_id)
            return Unexpected(make(StorageError::other_profile));
        if (hd.file_size != size || hd.count > max_entries)
            return Unexpected(make(StorageError::damaged));
        std::uint64_t end = page;
        for (std::uint32_t i = 0; i < hd.count; ++i) {
            const auto& e = hd.entries[i];
            // Sections are laid out in order, page aligned, inside the file (no sum
            // below may wrap: e.offset == end <= size is checked first).
            if (e.offset != end || e.offset > size || e.size > size - e.offset ||
                ::strnlen(e.name, name_size) == name_size)
                return Unexpected(make(StorageError::damaged));
            end = e.offset + round_up(std::max<std::uint64_t>(e.size, 1));
        }
        if (end != size) return Unexpected(make(StorageError::damaged));
        impl->existing = true;
        impl->claimed.assign(hd.count, false);
    } else {
        // New, or a file whose creation never finished (no write was ever acknowledged
        // from it): start over.
        if (::ftruncate(impl->fd, page) != 0)
            return Unexpected(std::error_code(errno, std::system_category()));
        std::memset(&hd, 0, page);
        hd.magic = file_magic;
        hd.version = file_version;
        std::memcpy(hd.profile, profile_id.data(), std::min(profile_id.size(), profile_size - 1));
        hd.file_size = page;
    }
    return std::unique_ptr<Storage>(new Storage(std::move(impl)));
}

std::span<std::byte> Storage::section(std::string_view name, std::size_t bytes, std::size_t,
                                      Retention retention) {
    Impl& s = *impl_;
    if (retention == Retention::cleared || s.fd < 0) return s.on_heap(bytes);
    FileHeader& hd = *s.header;
    if (s.existing) {
        for (std::uint32_t i = 0; i < hd.count; ++i) {
            const auto& e = hd.entries[i];
            if (name == std::string_view(e.name, ::strnlen(e.name, name_size))) {
                if (e.size != bytes || s.claimed[i]) break;
                s.claimed[i] = true;
                return s.map(e.offset, bytes);
            }
        }
        if (!s.problem) s.problem = make(StorageError::layout_mismatch);
        return s.on_heap(bytes);
    }
    if (hd.count >= max_entries || name.size() >= name_size) {
        if (!s.problem) s.problem = make(StorageError::too_many_sections);
        return s.on_heap(bytes);
    }
    // A duplicate could not be told apart from its twin when the file is reopened.
    for (std::uint32_t i = 0; i < hd.count; ++i)
        if (name ==
            std::string_view(hd.entries[i].name, ::strnlen(hd.entries[i].name, name_size))) {
            if (!s.problem) s.problem = make(StorageError::duplicate_section);
            return s.on_heap(bytes);
        }
    const std::uint64_t offset = hd.file_size;
    const std::uint64_t end = offset + round_up(std::max<std::size_t>(bytes, 1));
    if (::ftruncate(s.fd, static_cast<off_t>(end)) != 0) {
        if (!s.problem) s.problem = std::error_code(errno, std::system_category());
        return s.on_heap(bytes);
    }
    FileEntry& e = hd.entries[hd.count];
    std::memset(&e, 0, sizeof e);
    std::memcpy(e.name, name.data(), name.size());
    e.offset = offset;
    e.size = bytes;
    hd.file_size = end;
    ++hd.count;
    return s.map(offset, bytes);
}

Result<void> Storage::seal() {
    Impl& s = *impl_;
    if (s.problem) return Unexpected(s.problem);
    if (s.header == nullptr) return {};
    if (s.existing && std::find(s.claimed.begin(), s.claimed.end(), false) != s.claimed.end())
        return Unexpected(make(StorageError::layout_mismatch));
    s.header->complete = 1;
    ::msync(s.header, page, MS_SYNC);
    return {};
}

bool Storage::restored() const noexcept {
    return impl_->existing;
}

std::filesystem::path Storage::path() const {
    return impl_->path;
}

void Storage::flush() noexcept {
    for (auto [p, n] : impl_->maps)
        ::msync(p, n, MS_SYNC);
    if (impl_->header) ::msync(impl_->header, page, MS_SYNC);
}

}  // namespace fins::plc
