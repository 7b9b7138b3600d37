// The state file's host calls on Windows (contract and choices in storage_os.hpp).
#ifdef _WIN32
#include <windows.h>

#include <algorithm>

#include "plc/storage/storage_os.hpp"

namespace fins::plc::state_file::os {

namespace {

constexpr const wchar_t* lock_name = L"finsd.lock";

HANDLE h(Handle handle) noexcept {
    return reinterpret_cast<HANDLE>(handle);
}
Handle to_handle(HANDLE handle) noexcept {
    return handle == INVALID_HANDLE_VALUE ? none : reinterpret_cast<Handle>(handle);
}

std::error_code win_error(DWORD e) noexcept {
    return {static_cast<int>(e), std::system_category()};
}

std::filesystem::path in(const Directory& dir, const char* name) {
    return dir.path / name;
}

// Read and write for us; others may read (a copy, a backup) but neither write, nor
// truncate, nor open it for deletion while finsd has it (no FILE_SHARE_WRITE). Our own
// rename of an open file needs FILE_SHARE_DELETE.
Result<Handle> open(const std::filesystem::path& path, DWORD disposition) {
    const HANDLE f = ::CreateFileW(path.c_str(), GENERIC_READ | GENERIC_WRITE,
                                   FILE_SHARE_READ | FILE_SHARE_DELETE, nullptr, disposition,
                                   FILE_ATTRIBUTE_NORMAL | FILE_FLAG_OPEN_REPARSE_POINT, nullptr);
    if (f == INVALID_HANDLE_VALUE) return Unexpected(last_error());
    return to_handle(f);
}

}  // namespace

Directory::~Directory() {
    if (handle != none) ::CloseHandle(h(handle));  // releases the lock
}

std::error_code last_error() noexcept {
    return win_error(::GetLastError());
}

bool is_lock_conflict(const std::error_code& e) noexcept {
    return e == win_error(ERROR_LOCK_VIOLATION) || e == win_error(ERROR_SHARING_VIOLATION);
}

bool is_missing(const std::error_code& e) noexcept {
    return e == win_error(ERROR_FILE_NOT_FOUND) || e == win_error(ERROR_PATH_NOT_FOUND);
}

bool is_no_space(const std::error_code& e) noexcept {
    return e == win_error(ERROR_DISK_FULL) || e == win_error(ERROR_HANDLE_DISK_FULL) ||
           e == win_error(ERROR_FILE_TOO_LARGE);
}

Result<void> lock_directory(const std::filesystem::path& path, Directory& dir) {
    dir.path = path;
    const HANDLE f = ::CreateFileW((path / lock_name).c_str(), GENERIC_READ | GENERIC_WRITE,
                                   FILE_SHARE_READ | FILE_SHARE_WRITE, nullptr, OPEN_ALWAYS,
                                   FILE_ATTRIBUTE_NORMAL, nullptr);
    if (f == INVALID_HANDLE_VALUE) return Unexpected(last_error());
    dir.handle = to_handle(f);
    OVERLAPPED whole{};
    if (!::LockFileEx(f, LOCKFILE_EXCLUSIVE_LOCK | LOCKFILE_FAIL_IMMEDIATELY, 0, MAXDWORD, MAXDWORD,
                      &whole))
        return Unexpected(last_error());
    return {};
}

Result<Handle> open_file(const Directory& dir, const char* name) {
    return open(in(dir, name), OPEN_EXISTING);
}

Result<Handle> create_file(const Directory& dir, const char* name) {
    return open(in(dir, name), CREATE_ALWAYS);
}

void close(Handle file) noexcept {
    if (file != none) ::CloseHandle(h(file));
}

Result<bool> exists(const Directory& dir, const char* name) {
    if (::GetFileAttributesW(in(dir, name).c_str()) != INVALID_FILE_ATTRIBUTES) return true;
    const auto e = last_error();
    if (is_missing(e)) return false;
    return Unexpected(e);
}

Result<void> rename(const Directory& dir, const char* from, const char* to) {
    if (!::MoveFileExW(in(dir, from).c_str(), in(dir, to).c_str(),
                       MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH))
        return Unexpected(last_error());
    return {};
}

Result<void> link(const Directory& dir, const char* from, const char* to) {
    if (!::CreateHardLinkW(in(dir, to).c_str(), in(dir, from).c_str(), nullptr))
        return Unexpected(last_error());
    return {};
}

void remove(const Directory& dir, const char* name) noexcept {
    ::DeleteFileW(in(dir, name).c_str());
}

Result<void> sync(const Directory&) {
    return {};  // MOVEFILE_WRITE_THROUGH: the rename is on disk when MoveFileExW returns
}

Result<std::uint64_t> size(Handle file) {
    LARGE_INTEGER n{};
    if (!::GetFileSizeEx(h(file), &n)) return Unexpected(last_error());
    return static_cast<std::uint64_t>(n.QuadPart);
}

std::error_code reserve(Handle file, std::uint64_t offset, std::uint64_t length) noexcept {
    const std::uint64_t end = offset + length;
    auto current = size(file);
    if (!current) return current.error();
    if (*current >= end) return {};
    // Growing a file that is not sparse allocates its clusters on NTFS: a full disk is
    // ERROR_DISK_FULL here, never a failed write through a view later.
    LARGE_INTEGER at{};
    at.QuadPart = static_cast<LONGLONG>(end);
    if (!::SetFilePointerEx(h(file), at, nullptr, FILE_BEGIN) || !::SetEndOfFile(h(file)))
        return last_error();
    return {};
}

long long read_at(Handle file, void* buffer, std::size_t n, std::uint64_t offset) noexcept {
    OVERLAPPED at{};
    at.Offset = static_cast<DWORD>(offset);
    at.OffsetHigh = static_cast<DWORD>(offset >> 32);
    DWORD done = 0;
    const auto chunk = static_cast<DWORD>(std::min<std::size_t>(n, 1u << 30));
    if (!::ReadFile(h(file), buffer, chunk, &done, &at))
        return ::GetLastError() == ERROR_HANDLE_EOF ? 0 : -1;
    return done;
}

long long write_at(Handle file, const void* buffer, std::size_t n, std::uint64_t offset) noexcept {
    OVERLAPPED at{};
    at.Offset = static_cast<DWORD>(offset);
    at.OffsetHigh = static_cast<DWORD>(offset >> 32);
    DWORD done = 0;
    const auto chunk = static_cast<DWORD>(std::min<std::size_t>(n, 1u << 30));
    if (!::WriteFile(h(file), buffer, chunk, &done, &at)) return -1;
    return done;
}

Result<View> map(Handle file, std::uint64_t offset, std::size_t length, bool writable) {
    SYSTEM_INFO info{};
    ::GetSystemInfo(&info);
    const std::uint64_t granularity = info.dwAllocationGranularity;
    const std::uint64_t start = offset / granularity * granularity;
    const std::uint64_t end = offset + length;
    const HANDLE mapping =
        ::CreateFileMappingW(h(file), nullptr, writable ? PAGE_READWRITE : PAGE_READONLY,
                             static_cast<DWORD>(end >> 32), static_cast<DWORD>(end), nullptr);
    if (mapping == nullptr) return Unexpected(last_error());
    const auto span = static_cast<std::size_t>(end - start);
    void* base = ::MapViewOfFile(mapping, writable ? FILE_MAP_WRITE : FILE_MAP_READ,
                                 static_cast<DWORD>(start >> 32), static_cast<DWORD>(start), span);
    const auto e = last_error();
    ::CloseHandle(mapping);  // the view keeps the section
    if (base == nullptr) return Unexpected(e);
    return View{base, span, static_cast<std::byte*>(base) + (offset - start)};
}

void unmap(void* base, std::size_t) noexcept {
    ::UnmapViewOfFile(base);
}

void flush(void* base, std::size_t span) noexcept {
    ::FlushViewOfFile(base, span);
}

bool sync_data(Handle file, std::span<const std::pair<void*, std::size_t>> views,
               std::pair<void*, std::size_t> header) noexcept {
    bool ok = true;
    for (auto [base, span] : views)
        ok = ::FlushViewOfFile(base, span) != 0 && ok;
    if (header.first != nullptr) ok = ::FlushViewOfFile(header.first, header.second) != 0 && ok;
    return ::FlushFileBuffers(h(file)) != 0 && ok;
}

void* reserve_zeroed(std::size_t length) noexcept {
    // Committed pages are zero and take memory only when first touched.
    return ::VirtualAlloc(nullptr, length, MEM_RESERVE | MEM_COMMIT, PAGE_READWRITE);
}

void release_zeroed(void* p, std::size_t) noexcept {
    ::VirtualFree(p, 0, MEM_RELEASE);
}

}  // namespace fins::plc::state_file::os
#endif
