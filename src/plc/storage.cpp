#include "plc/storage.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <vector>

#include "plc/crc32c.hpp"
#include "plc/storage_chunks.hpp"
#include "plc/storage_format.hpp"
#include "plc/storage_guard.hpp"

namespace fins::plc {

namespace {

namespace sf = state_file;
using sf::Error;
using sf::page;

constexpr const char* file_name = "finsd.state";
constexpr const char* temp_name = "finsd.state.new";

void (*creation_probe)(const char*) = nullptr;

void step(const char* name) {
    if (creation_probe != nullptr) creation_probe(name);
}

std::error_code make(Error e) {
    return sf::make_error(e);
}
std::error_code last_error() {
    return {errno, std::system_category()};
}
// posix_fallocate's result: a reservation that does not fit is no_space.
std::error_code reserve_error(int e) {
    if (e == ENOSPC || e == EDQUOT || e == EFBIG) return make(Error::no_space);
    return {e, std::system_category()};
}

std::string_view entry_name(const sf::Entry& e) {
    return {e.name, ::strnlen(e.name, sf::name_size)};
}

Unexpected fail(std::error_code e) {
    return Unexpected(e);
}

}  // namespace

struct Storage::Impl {
    // Sections not in the file, and those it could not map.
    SectionChunks unmapped;
    int dir_fd = -1;  // the data directory, locked (flock) for the Storage's life
    int fd = -1;
    sf::Header* header = nullptr;
    std::vector<std::pair<void*, std::size_t>> maps;
    std::vector<std::span<std::byte>> sections;  // by entry index
    std::vector<bool> claimed;                   // per existing entry
    bool existing = false;                       // restored from finsd.state
    bool creating = false;                       // building finsd.state.new
    bool verified = false;
    bool sealed = false;
    bool closed = false;
    bool upgraded = false;  // converted from a version 1 file
    std::error_code problem;
    std::filesystem::path path;
    // From seal() on: the file's size and its mappings under the SIGBUS guard.
    std::uint64_t sealed_size = 0;
    std::vector<std::pair<void*, std::size_t>> guarded;
    std::unique_ptr<StateFileGuard> guard;

    std::span<std::byte> map(std::uint64_t offset, std::size_t bytes) {
        const std::size_t length = round_up_to_page(bytes);
        void* p = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd,
                         static_cast<off_t>(offset));
        if (p == MAP_FAILED) {
            if (!problem) problem = last_error();
            return unmapped.allocate(bytes);
        }
        maps.emplace_back(p, length);
        return {static_cast<std::byte*>(p), bytes};
    }

    Result<void> map_header() {
        void* h = ::mmap(nullptr, page, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
        if (h == MAP_FAILED) return fail(last_error());
        header = static_cast<sf::Header*>(h);
        return {};
    }

    // The seal block: `clean` with the checksums of every section, or "running".
    void write_seal(bool clean) {
        sf::Seal& seal = header->seal;
        std::memset(&seal, 0, sizeof seal);
        if (clean) {
            for (std::size_t i = 0; i < sections.size(); ++i)
                seal.section_crc[i] = crc32c(sections[i]);
            seal.clean = sf::clean_mark;
        }
        seal.crc = sf::crc_without(seal, seal.crc);
    }

    Result<void> create(std::string_view profile_id);
    Result<void> restore(std::string_view profile_id);

    ~Impl() {
        guard.reset();  // before the mappings go
        for (auto [p, n] : maps)
            ::munmap(p, n);
        if (header != nullptr) ::munmap(header, page);
        if (fd >= 0) ::close(fd);
        // An unfinished build is ours (the lock): nothing else ever reads it.
        if (creating) ::unlinkat(dir_fd, temp_name, 0);
        if (dir_fd >= 0) ::close(dir_fd);
    }
};

// A new file is built under temp_name: every byte reserved, header first; seal()
// completes it and renames it into place.
Result<void> Storage::Impl::create(std::string_view profile_id) {
    step("locked");
    fd = ::openat(dir_fd, temp_name, O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return fail(last_error());
    creating = true;
    step("temporary file created");
    if (const int e = ::posix_fallocate(fd, 0, page); e != 0) return fail(reserve_error(e));
    if (auto r = map_header(); !r) return r;
    sf::Descriptor& d = header->descriptor;
    d.magic = sf::magic;
    d.version = sf::version;
    std::memcpy(d.profile, profile_id.data(), profile_id.size());
    d.file_size = page;
    step("header written");
    return {};
}

// An existing finsd.state: every check before the first byte is written to it.
Result<void> Storage::Impl::restore(std::string_view profile_id) {
    struct stat st {};
    if (::fstat(fd, &st) != 0) return fail(last_error());
    const auto size = static_cast<std::uint64_t>(st.st_size);
    if (size == 0) return fail(make(Error::empty));
    if (size < page) return fail(make(Error::not_a_state_file));
    if (auto r = map_header(); !r) return r;
    const sf::Descriptor& d = header->descriptor;
    if (d.magic != sf::magic) return fail(make(Error::not_a_state_file));
    if (d.version == 1 && !upgraded) {
        // Converted into a new file (the old one kept as finsd.state.version1), then
        // checked as any other.
        auto converted = sf::convert_version1(dir_fd, fd, size);
        if (!converted) return fail(converted.error());
        ::munmap(header, page);
        header = nullptr;
        ::close(fd);
        fd = *converted;
        upgraded = true;
        return restore(profile_id);
    }
    if (d.version != sf::version) return fail(make(Error::unsupported_version));
    if (d.complete != sf::complete_mark) return fail(make(Error::incomplete));
    if (d.crc != sf::crc_without(d, d.crc)) return fail(make(Error::header_checksum));
    if (std::string_view(d.profile, ::strnlen(d.profile, sf::profile_size)) != profile_id)
        return fail(make(Error::other_profile));
    if (d.file_size != size || d.count > sf::max_entries) return fail(make(Error::damaged));
    std::uint64_t end = page;
    for (std::uint32_t i = 0; i < d.count; ++i) {
        const auto& e = d.entries[i];
        // Sections are laid out in order, page aligned, inside the file (no sum below
        // may wrap: e.offset == end <= size is checked first).
        if (e.offset != end || e.offset > size || e.size > size - e.offset ||
            ::strnlen(e.name, sf::name_size) == sf::name_size)
            return fail(make(Error::damaged));
        end = e.offset + round_up_to_page(e.size);
    }
    if (end != size) return fail(make(Error::damaged));
    const sf::Seal& seal = header->seal;
    if (seal.crc != sf::crc_without(seal, seal.crc)) return fail(make(Error::header_checksum));
    if (seal.clean == sf::clean_mark) {
        if (auto r = sf::verify_section_checksums(fd, size, *header); !r) return r;
        verified = true;
    }
    // A sparse file (an older finsd, a copy) gets its holes reserved now: a write to a
    // page never needs disk space later, so a full disk cannot SIGBUS finsd.
    if (const int e = ::posix_fallocate(fd, 0, static_cast<off_t>(size)); e != 0)
        return fail(reserve_error(e));
    existing = true;
    claimed.assign(d.count, false);
    sections.assign(d.count, {});
    return {};
}

Storage::Storage() : impl_(std::make_unique<Impl>()) {}
Storage::Storage(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Storage::~Storage() {
    close();
}

Result<std::unique_ptr<Storage>> Storage::open(const std::filesystem::path& dir,
                                               std::string_view profile_id,
                                               StorageOptions options) {
    // The header keeps the id NUL-terminated; a longer one could never match again.
    if (profile_id.size() >= sf::profile_size) return fail(make(Error::profile_id_too_long));
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) return fail(ec);
    auto impl = std::make_unique<Impl>();
    impl->path = dir / file_name;
    impl->dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (impl->dir_fd < 0) return fail(last_error());
    if (::flock(impl->dir_fd, LOCK_EX | LOCK_NB) != 0)
        return fail(errno == EWOULDBLOCK ? make(Error::in_use) : last_error());
    impl->fd = ::openat(impl->dir_fd, file_name, O_RDWR | O_CLOEXEC);
    if (impl->fd < 0 && errno != ENOENT) return fail(last_error());
    const auto opened = impl->fd >= 0 ? impl->restore(profile_id) : impl->create(profile_id);
    if (!opened) return fail(opened.error());
    std::unique_ptr<Storage> storage(new Storage(std::move(impl)));
    storage->sync_on_commit_ = options.durability == Durability::power;
    return storage;
}

bool Storage::is_refusal(const std::error_code& error) noexcept {
    return sf::is_refusal(error);
}

Result<std::filesystem::path> Storage::set_aside(const std::filesystem::path& dir) {
    Impl lock;  // closes the directory (and so releases the lock) on every return
    lock.dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (lock.dir_fd < 0) return fail(last_error());
    if (::flock(lock.dir_fd, LOCK_EX | LOCK_NB) != 0)
        return fail(errno == EWOULDBLOCK ? make(Error::in_use) : last_error());
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    ::gmtime_r(&now, &utc);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &utc);
    const std::string base = std::string(file_name) + ".replaced-" + stamp;
    for (int n = 1; n <= 100; ++n) {
        const std::string name = n == 1 ? base : base + "-" + std::to_string(n);
        struct stat st {};
        if (::fstatat(lock.dir_fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0) continue;
        if (errno != ENOENT) return fail(last_error());
        // Under the lock nothing else creates names here: the free name stays free.
        if (::renameat(lock.dir_fd, file_name, lock.dir_fd, name.c_str()) != 0)
            return fail(last_error());
        if (::fsync(lock.dir_fd) != 0) return fail(last_error());
        return dir / name;
    }
    return fail(std::make_error_code(std::errc::file_exists));
}

std::span<std::byte> Storage::section(std::string_view name, std::size_t bytes, std::size_t,
                                      Retention retention) {
    Impl& s = *impl_;
    if (retention == Retention::cleared || s.fd < 0) return s.unmapped.allocate(bytes);
    sf::Descriptor& d = s.header->descriptor;
    if (s.existing) {
        for (std::uint32_t i = 0; i < d.count; ++i) {
            const auto& e = d.entries[i];
            if (name == entry_name(e)) {
                if (e.size != bytes || s.claimed[i]) break;
                s.claimed[i] = true;
                s.sections[i] = s.map(e.offset, bytes);
                return s.sections[i];
            }
        }
        if (!s.problem) s.problem = make(Error::layout_mismatch);
        return s.unmapped.allocate(bytes);
    }
    if (d.count >= sf::max_entries || name.size() >= sf::name_size) {
        if (!s.problem) s.problem = make(Error::too_many_sections);
        return s.unmapped.allocate(bytes);
    }
    // A duplicate could not be told apart from its twin when the file is reopened.
    for (std::uint32_t i = 0; i < d.count; ++i)
        if (name == entry_name(d.entries[i])) {
            if (!s.problem) s.problem = make(Error::duplicate_section);
            return s.unmapped.allocate(bytes);
        }
    const std::uint64_t offset = d.file_size;
    const std::uint64_t length = round_up_to_page(bytes);
    if (const int e =
            ::posix_fallocate(s.fd, static_cast<off_t>(offset), static_cast<off_t>(length));
        e != 0) {
        if (!s.problem) s.problem = reserve_error(e);
        return s.unmapped.allocate(bytes);
    }
    sf::Entry& e = d.entries[d.count];
    std::memset(&e, 0, sizeof e);
    std::memcpy(e.name, name.data(), name.size());
    e.offset = offset;
    e.size = bytes;
    d.file_size = offset + length;
    ++d.count;
    s.sections.push_back(s.map(offset, bytes));
    step("section reserved");
    return s.sections.back();
}

Result<void> Storage::seal() {
    Impl& s = *impl_;
    if (s.problem) return fail(s.problem);
    if (s.header == nullptr || s.sealed) return {};
    if (s.existing && std::find(s.claimed.begin(), s.claimed.end(), false) != s.claimed.end())
        return fail(make(Error::layout_mismatch));
    // From here on finsd serves and the section checksums stop holding: "running" is on
    // disk before the first answer, so no crash can leave "clean" over changed data.
    s.write_seal(false);
    if (s.creating) {
        sf::Descriptor& d = s.header->descriptor;
        d.complete = sf::complete_mark;
        d.crc = sf::crc_without(d, d.crc);
    }
    if (::fdatasync(s.fd) != 0) return fail(last_error());
    if (s.creating) {
        step("synced");
        if (::renameat(s.dir_fd, temp_name, s.dir_fd, file_name) != 0) return fail(last_error());
        s.creating = false;
        step("renamed");
        if (::fsync(s.dir_fd) != 0) return fail(last_error());
        step("directory synced");
    }
    s.sealed = true;
    s.sealed_size = s.header->descriptor.file_size;
    s.guarded = s.maps;
    s.guarded.emplace_back(s.header, page);
    s.guard = std::make_unique<StateFileGuard>(s.guarded, s.path.string());
    return {};
}

bool Storage::restored() const noexcept {
    return impl_->existing;
}

bool Storage::checksums_verified() const noexcept {
    return impl_->verified;
}

std::filesystem::path Storage::path() const {
    return impl_->path;
}

bool Storage::intact() const noexcept {
    const Impl& s = *impl_;
    if (!s.sealed || s.fd < 0) return true;
    struct stat st {};
    return ::fstat(s.fd, &st) == 0 && static_cast<std::uint64_t>(st.st_size) >= s.sealed_size;
}

void Storage::flush() noexcept {
    for (auto [p, n] : impl_->maps)
        ::msync(p, n, MS_SYNC);
    if (impl_->header != nullptr) ::msync(impl_->header, page, MS_SYNC);
}

void Storage::close() noexcept {
    Impl& s = *impl_;
    if (!s.sealed || s.closed) return;
    s.closed = true;
    // A file that shrank under us is left as it is: sealing it would touch pages that
    // are gone (SIGBUS) and could mark lost data "clean".
    if (!intact()) return;
    // Sections first: checksums never describe data that is not on disk. When a sync
    // fails the file stays "running" and is checked as after a SIGKILL.
    if (::fdatasync(s.fd) != 0) return;
    s.write_seal(true);
    ::fdatasync(s.fd);
}

bool Storage::sync() noexcept {
    ++syncs_;
    return impl_->fd >= 0 && ::fdatasync(impl_->fd) == 0;
}

void Storage::set_creation_probe(void (*probe)(const char* step)) noexcept {
    creation_probe = probe;
}

}  // namespace fins::plc
