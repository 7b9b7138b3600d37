#include "plc/storage/storage.hpp"

#include <algorithm>
#include <cstring>
#include <ctime>
#include <vector>

#include "plc/storage/crc32c.hpp"
#include "plc/storage/storage_chunks.hpp"
#include "plc/storage/storage_format.hpp"
#include "plc/storage/storage_guard.hpp"
#include "plc/storage/storage_os.hpp"

namespace fins::plc {

namespace os = state_file::os;

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
using os::last_error;
// A reservation's result: one that does not fit is no_space.
std::error_code reserve_error(std::error_code e) {
    if (os::is_no_space(e)) return make(Error::no_space);
    return e;
}
// The UTC time `now` as YYYYMMDDTHHMMSSZ.
std::string utc_stamp(std::time_t now) {
    std::tm utc{};
    ::gmtime_r(&now, &utc);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &utc);
    return stamp;
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
    os::Directory dir;  // the data directory, locked for the Storage's life
    os::Handle fd = os::none;
    sf::Header* header = nullptr;
    std::size_t header_span = 0;
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
        auto view = os::map(fd, offset, length, true);
        if (!view) {
            if (!problem) problem = view.error();
            return unmapped.allocate(bytes);
        }
        maps.emplace_back(view->base, view->span);
        return {view->data, bytes};
    }

    Result<void> map_header() {
        auto view = os::map(fd, 0, page, true);
        if (!view) return fail(view.error());
        header = reinterpret_cast<sf::Header*>(view->data);
        header_span = view->span;
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

    // The file's data on disk, its views included (fdatasync; FlushViewOfFile and
    // FlushFileBuffers on Windows).
    bool sync_data() noexcept { return os::sync_data(fd, maps, {header, header_span}); }

    Result<void> create(std::string_view profile_id);
    Result<void> restore(std::string_view profile_id);

    ~Impl() {
        guard.reset();  // before the mappings go
        for (auto [p, n] : maps)
            os::unmap(p, n);
        if (header != nullptr) os::unmap(header, header_span);
        os::close(fd);
        // An unfinished build is ours (the lock): nothing else ever reads it.
        if (creating) os::remove(dir, temp_name);
    }
};

// A new file is built under temp_name: every byte reserved, header first; seal()
// completes it and renames it into place.
Result<void> Storage::Impl::create(std::string_view profile_id) {
    step("locked");
    auto created = os::create_file(dir, temp_name);
    if (!created) return fail(created.error());
    fd = *created;
    creating = true;
    step("temporary file created");
    if (const auto e = os::reserve(fd, 0, page)) return fail(reserve_error(e));
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
    const auto file_size = os::size(fd);
    if (!file_size) return fail(file_size.error());
    const std::uint64_t size = *file_size;
    if (size == 0) return fail(make(Error::empty));
    if (size < page) return fail(make(Error::not_a_state_file));
    if (auto r = map_header(); !r) return r;
    const sf::Descriptor& d = header->descriptor;
    if (d.magic != sf::magic) return fail(make(Error::not_a_state_file));
    if (d.version == 1 && !upgraded) {
        // Converted into a new file (the old one kept as finsd.state.version1), then
        // checked as any other.
        auto converted = sf::convert_version1(dir, fd, size);
        if (!converted) return fail(converted.error());
        os::unmap(header, header_span);
        header = nullptr;
        os::close(fd);
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
    if (const auto e = os::reserve(fd, 0, size)) return fail(reserve_error(e));
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
    if (auto locked = os::lock_directory(dir, impl->dir); !locked)
        return fail(os::is_lock_conflict(locked.error()) ? make(Error::in_use) : locked.error());
    auto existing = os::open_file(impl->dir, file_name);
    if (!existing && !os::is_missing(existing.error())) return fail(existing.error());
    if (existing) impl->fd = *existing;
    const auto opened = existing ? impl->restore(profile_id) : impl->create(profile_id);
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
    if (auto locked = os::lock_directory(dir, lock.dir); !locked)
        return fail(os::is_lock_conflict(locked.error()) ? make(Error::in_use) : locked.error());
    const std::string base = std::string(file_name) + ".replaced-" + utc_stamp(std::time(nullptr));
    for (int n = 1; n <= 100; ++n) {
        const std::string name = n == 1 ? base : base + "-" + std::to_string(n);
        const auto taken = os::exists(lock.dir, name.c_str());
        if (!taken) return fail(taken.error());
        if (*taken) continue;
        // Under the lock nothing else creates names here: the free name stays free.
        if (auto r = os::rename(lock.dir, file_name, name.c_str()); !r) return fail(r.error());
        if (auto r = os::sync(lock.dir); !r) return fail(r.error());
        return dir / name;
    }
    return fail(std::make_error_code(std::errc::file_exists));
}

std::span<std::byte> Storage::section(std::string_view name, std::size_t bytes, std::size_t,
                                      Retention retention) {
    Impl& s = *impl_;
    if (retention == Retention::cleared || s.fd == os::none) return s.unmapped.allocate(bytes);
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
    if (const auto e = os::reserve(s.fd, offset, length)) {
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
    if (!s.sync_data()) return fail(last_error());
    if (s.creating) {
        step("synced");
        if (auto r = os::rename(s.dir, temp_name, file_name); !r) return r;
        s.creating = false;
        step("renamed");
        if (auto r = os::sync(s.dir); !r) return r;
        step("directory synced");
    }
    s.sealed = true;
    s.sealed_size = s.header->descriptor.file_size;
    s.guarded = s.maps;
    s.guarded.emplace_back(s.header, s.header_span);
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
    if (!s.sealed || s.fd == os::none) return true;
    const auto size = os::size(s.fd);
    return size && *size >= s.sealed_size;
}

void Storage::flush() noexcept {
    for (auto [p, n] : impl_->maps)
        os::flush(p, n);
    if (impl_->header != nullptr) os::flush(impl_->header, impl_->header_span);
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
    if (!s.sync_data()) return;
    s.write_seal(true);
    s.sync_data();
}

bool Storage::sync() noexcept {
    ++syncs_;
    return impl_->fd != os::none && impl_->sync_data();
}

void Storage::set_creation_probe(void (*probe)(const char* step)) noexcept {
    creation_probe = probe;
}

}  // namespace fins::plc
