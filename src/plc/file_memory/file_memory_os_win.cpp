// plc::FileMemory's host calls on Windows (see file_memory_os.hpp): wide-char Win32
// calls on "<verified directory path>\<one checked name>". Every open is checked after
// the fact: no reparse point (symlink, junction, mount point) and a final path
// (GetFinalPathNameByHandleW) exactly the one asked for, else it is closed and refused
// as a link would be on Linux (a Unix symlink under wine shows only in the final path).
#ifdef _WIN32
#include <windows.h>

#include <algorithm>
#include <cwchar>
#include <mutex>
#include <random>

#include "plc/file_memory/file_memory_os.hpp"

namespace fins::plc::host {

namespace {

// The handles behind the ints, each with the final path it was verified at.
struct Slot {
    HANDLE handle = INVALID_HANDLE_VALUE;
    std::wstring path;
};

std::mutex table_mutex;
std::vector<Slot>& table() {
    static std::vector<Slot> slots;
    return slots;
}

int add(HANDLE handle, std::wstring path) {
    const std::lock_guard lock(table_mutex);
    auto& slots = table();
    for (std::size_t i = 0; i < slots.size(); ++i)
        if (slots[i].handle == INVALID_HANDLE_VALUE) {
            slots[i] = {handle, std::move(path)};
            return static_cast<int>(i);
        }
    slots.push_back({handle, std::move(path)});
    return static_cast<int>(slots.size() - 1);
}

Slot get(int handle) {
    const std::lock_guard lock(table_mutex);
    const auto& slots = table();
    if (handle < 0 || static_cast<std::size_t>(handle) >= slots.size()) return {};
    return slots[static_cast<std::size_t>(handle)];
}

std::wstring widen(const std::string& text) {
    if (text.empty()) return {};
    const int n =
        ::MultiByteToWideChar(CP_UTF8, 0, text.data(), static_cast<int>(text.size()), nullptr, 0);
    std::wstring out(static_cast<std::size_t>(n), L'\0');
    ::MultiByteToWideChar(CP_UTF8, 0, text.data(), static_cast<int>(text.size()), out.data(), n);
    return out;
}

std::string narrow(const wchar_t* text) {
    const int n = ::WideCharToMultiByte(CP_UTF8, 0, text, -1, nullptr, 0, nullptr, nullptr);
    if (n <= 1) return {};
    std::string out(static_cast<std::size_t>(n), '\0');
    ::WideCharToMultiByte(CP_UTF8, 0, text, -1, out.data(), n, nullptr, nullptr);
    out.resize(static_cast<std::size_t>(n - 1));
    return out;
}

// "<dir's path>\<name>"; empty when `dir` is no open handle.
std::wstring child(int dir, const std::string& name) {
    const Slot s = get(dir);
    if (s.handle == INVALID_HANDLE_VALUE || name.empty()) return {};
    return s.path + L'\\' + widen(name);
}

std::wstring final_path(HANDLE h) {
    std::wstring out(MAX_PATH, L'\0');
    for (int attempt = 0; attempt < 3; ++attempt) {
        const DWORD n = ::GetFinalPathNameByHandleW(h, out.data(), static_cast<DWORD>(out.size()),
                                                    FILE_NAME_NORMALIZED | VOLUME_NAME_DOS);
        if (n == 0) return {};
        if (n < out.size()) {
            out.resize(n);
            return out;
        }
        out.resize(n + 1);
    }
    return {};
}

constexpr DWORD share_all = FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE;
// Directories: without FILE_SHARE_DELETE, nobody renames or removes one while it is open.
constexpr DWORD share_directory = FILE_SHARE_READ | FILE_SHARE_WRITE;
constexpr DWORD directory_access = FILE_LIST_DIRECTORY | FILE_READ_ATTRIBUTES | SYNCHRONIZE;
constexpr std::int64_t filetime_unix_offset = 11644473600LL;  // 1601-01-01 .. 1970-01-01

Info info_of(const BY_HANDLE_FILE_INFORMATION& i) {
    Info out;
    out.kind = (i.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY) != 0 ? Kind::directory : Kind::file;
    out.size = (std::uint64_t{i.nFileSizeHigh} << 32) | i.nFileSizeLow;
    const auto ticks = static_cast<std::int64_t>(
        (std::uint64_t{i.ftLastWriteTime.dwHighDateTime} << 32) | i.ftLastWriteTime.dwLowDateTime);
    out.mtime = ticks / 10'000'000 - filetime_unix_offset;
    out.device = i.dwVolumeSerialNumber;
    out.inode = (std::uint64_t{i.nFileIndexHigh} << 32) | i.nFileIndexLow;
    return out;
}

enum class Want : std::uint8_t { file, directory, any };

// Opens `path` without following a reparse point and checks what was opened: INVALID
// (and `refused` set when something was there but is a link or the wrong kind).
HANDLE open_checked(const std::wstring& path, DWORD access, DWORD share, DWORD disposition,
                    Want want, Info* info = nullptr, bool* refused = nullptr) {
    if (path.empty()) return INVALID_HANDLE_VALUE;
    HANDLE h = ::CreateFileW(path.c_str(), access, share, nullptr, disposition,
                             FILE_FLAG_OPEN_REPARSE_POINT | FILE_FLAG_BACKUP_SEMANTICS, nullptr);
    if (h == INVALID_HANDLE_VALUE) return h;
    BY_HANDLE_FILE_INFORMATION i{};
    const bool ok = ::GetFileInformationByHandle(h, &i) != 0 &&
                    (i.dwFileAttributes & FILE_ATTRIBUTE_REPARSE_POINT) == 0 &&
                    final_path(h) == path;
    const Info got = ok ? info_of(i) : Info{};
    if (!ok || (want == Want::file && got.kind != Kind::file) ||
        (want == Want::directory && got.kind != Kind::directory)) {
        ::CloseHandle(h);
        if (refused != nullptr) *refused = true;
        return INVALID_HANDLE_VALUE;
    }
    if (info != nullptr) *info = got;
    return h;
}

FILETIME filetime_of(std::int64_t mtime) noexcept {
    const auto ticks = static_cast<std::uint64_t>((mtime + filetime_unix_offset) * 10'000'000);
    FILETIME t{};
    t.dwLowDateTime = static_cast<DWORD>(ticks & 0xFFFFFFFFU);
    t.dwHighDateTime = static_cast<DWORD>(ticks >> 32);
    return t;
}

std::error_code last_error() {
    return {static_cast<int>(::GetLastError()), std::system_category()};
}

}  // namespace

void close(int handle) noexcept {
    if (handle < 0) return;
    HANDLE h = INVALID_HANDLE_VALUE;
    {
        const std::lock_guard lock(table_mutex);
        auto& slots = table();
        if (static_cast<std::size_t>(handle) >= slots.size()) return;
        auto& s = slots[static_cast<std::size_t>(handle)];
        h = s.handle;
        s.handle = INVALID_HANDLE_VALUE;
        s.path.clear();
    }
    if (h != INVALID_HANDLE_VALUE) ::CloseHandle(h);
}

int duplicate(int handle) noexcept {
    try {
        Slot s = get(handle);
        HANDLE copy = INVALID_HANDLE_VALUE;
        if (s.handle == INVALID_HANDLE_VALUE ||
            ::DuplicateHandle(::GetCurrentProcess(), s.handle, ::GetCurrentProcess(), &copy, 0,
                              FALSE, DUPLICATE_SAME_ACCESS) == 0)
            return -1;
        return add(copy, std::move(s.path));
    } catch (...) {
        return -1;
    }
}

int open_root(const std::filesystem::path& root, std::error_code& error) noexcept {
    try {
        const auto absolute = std::filesystem::absolute(root, error);
        if (error) return -1;
        HANDLE h = ::CreateFileW(absolute.c_str(), directory_access, share_directory, nullptr,
                                 OPEN_EXISTING, FILE_FLAG_BACKUP_SEMANTICS, nullptr);
        if (h == INVALID_HANDLE_VALUE) {
            error = last_error();
            return -1;
        }
        BY_HANDLE_FILE_INFORMATION i{};
        auto path = final_path(h);
        if (::GetFileInformationByHandle(h, &i) == 0 || path.empty() ||
            (i.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY) == 0) {
            ::CloseHandle(h);
            error = std::make_error_code(std::errc::not_a_directory);
            return -1;
        }
        return add(h, std::move(path));
    } catch (...) {
        error = std::make_error_code(std::errc::not_enough_memory);
        return -1;
    }
}

bool is_link(int dir, const std::string& name) noexcept {
    try {
        const auto path = child(dir, name);
        const DWORD attributes = ::GetFileAttributesW(path.c_str());
        if (path.empty() || attributes == INVALID_FILE_ATTRIBUTES) return false;
        if ((attributes & FILE_ATTRIBUTE_REPARSE_POINT) != 0) return true;
        bool refused = false;
        HANDLE h = open_checked(path, FILE_READ_ATTRIBUTES, share_all, OPEN_EXISTING, Want::any,
                                nullptr, &refused);
        if (h != INVALID_HANDLE_VALUE) ::CloseHandle(h);
        return refused;
    } catch (...) {
        return false;
    }
}

int open_linked_directory(int dir, const std::string& name, std::error_code& error) noexcept {
    try {
        const auto path = child(dir, name);
        HANDLE h = ::CreateFileW(path.c_str(), directory_access, share_directory, nullptr,
                                 OPEN_EXISTING, FILE_FLAG_BACKUP_SEMANTICS, nullptr);
        if (h == INVALID_HANDLE_VALUE) {
            error = last_error();
            return -1;
        }
        BY_HANDLE_FILE_INFORMATION i{};
        auto target = final_path(h);
        if (::GetFileInformationByHandle(h, &i) == 0 || target.empty() ||
            (i.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY) == 0) {
            ::CloseHandle(h);
            error = std::make_error_code(std::errc::not_a_directory);
            return -1;
        }
        return add(h, std::move(target));
    } catch (...) {
        error = std::make_error_code(std::errc::not_enough_memory);
        return -1;
    }
}

int open_directory(int dir, const std::string& name) noexcept {
    try {
        auto path = child(dir, name);
        HANDLE h =
            open_checked(path, directory_access, share_directory, OPEN_EXISTING, Want::directory);
        return h == INVALID_HANDLE_VALUE ? -1 : add(h, std::move(path));
    } catch (...) {
        return -1;
    }
}

Kind stat_at(int dir, const std::string& name, Info* info, bool) noexcept {
    try {
        const auto path = child(dir, name);
        if (path.empty() || ::GetFileAttributesW(path.c_str()) == INVALID_FILE_ATTRIBUTES)
            return Kind::missing;
        Info got;
        bool refused = false;
        HANDLE h = open_checked(path, FILE_READ_ATTRIBUTES, share_all, OPEN_EXISTING, Want::any,
                                &got, &refused);
        if (h == INVALID_HANDLE_VALUE) return refused ? Kind::other : Kind::missing;
        ::CloseHandle(h);
        if (info != nullptr) *info = got;
        return got.kind;
    } catch (...) {
        return Kind::missing;
    }
}

bool stat(int handle, Info& info) noexcept {
    const Slot s = get(handle);
    BY_HANDLE_FILE_INFORMATION i{};
    if (s.handle == INVALID_HANDLE_VALUE || ::GetFileInformationByHandle(s.handle, &i) == 0)
        return false;
    info = info_of(i);
    return true;
}

int open_file(int dir, const std::string& name, Access access) noexcept {
    try {
        auto path = child(dir, name);
        const DWORD rights = access == Access::read    ? GENERIC_READ
                             : access == Access::write ? GENERIC_WRITE
                                                       : GENERIC_READ | GENERIC_WRITE;
        HANDLE h = open_checked(path, rights, share_all, OPEN_EXISTING, Want::file);
        return h == INVALID_HANDLE_VALUE ? -1 : add(h, std::move(path));
    } catch (...) {
        return -1;
    }
}

int create_file(int dir, const std::string& name, bool& exists) noexcept {
    exists = false;
    try {
        auto path = child(dir, name);
        if (path.empty()) return -1;
        HANDLE h = ::CreateFileW(path.c_str(), GENERIC_WRITE, share_all, nullptr, CREATE_NEW,
                                 FILE_ATTRIBUTE_NORMAL | FILE_FLAG_OPEN_REPARSE_POINT, nullptr);
        if (h == INVALID_HANDLE_VALUE) {
            const DWORD e = ::GetLastError();
            exists = e == ERROR_FILE_EXISTS || e == ERROR_ALREADY_EXISTS;
            return -1;
        }
        if (final_path(h) != path) {  // the directory is not where it was checked
            ::CloseHandle(h);
            return -1;
        }
        return add(h, std::move(path));
    } catch (...) {
        return -1;
    }
}

std::vector<std::string> names(int dir) {
    std::vector<std::string> out;
    const auto pattern = child(dir, "*");
    if (pattern.empty()) return out;
    WIN32_FIND_DATAW found{};
    HANDLE h = ::FindFirstFileW(pattern.c_str(), &found);
    if (h == INVALID_HANDLE_VALUE) return out;
    do {
        const std::wstring_view n = found.cFileName;
        if (n != L"." && n != L"..") out.push_back(narrow(found.cFileName));
    } while (::FindNextFileW(h, &found) != 0);
    ::FindClose(h);
    return out;
}

Status make_directory(int dir, const std::string& name) noexcept {
    try {
        const auto path = child(dir, name);
        if (!path.empty() && ::CreateDirectoryW(path.c_str(), nullptr) != 0) return Status::ok;
        return ::GetLastError() == ERROR_ALREADY_EXISTS ? Status::exists : Status::failed;
    } catch (...) {
        return Status::failed;
    }
}

Status remove(int dir, const std::string& name, bool directory) noexcept {
    try {
        const auto path = child(dir, name);
        if (path.empty()) return Status::failed;
        if ((directory ? ::RemoveDirectoryW(path.c_str()) : ::DeleteFileW(path.c_str())) != 0)
            return Status::ok;
        return ::GetLastError() == ERROR_DIR_NOT_EMPTY ? Status::not_empty : Status::failed;
    } catch (...) {
        return Status::failed;
    }
}

bool rename(int dir, const std::string& from, const std::string& to) noexcept {
    try {
        const auto source = child(dir, from);
        const auto target = child(dir, to);
        return !source.empty() && !target.empty() &&
               ::MoveFileExW(source.c_str(), target.c_str(),
                             MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH) != 0;
    } catch (...) {
        return false;
    }
}

long long read_at(int handle, std::uint8_t* data, std::size_t size, std::uint64_t offset) noexcept {
    const Slot s = get(handle);
    OVERLAPPED at{};
    at.Offset = static_cast<DWORD>(offset & 0xFFFFFFFFU);
    at.OffsetHigh = static_cast<DWORD>(offset >> 32);
    DWORD got = 0;
    const auto n = static_cast<DWORD>(std::min<std::size_t>(size, 1U << 30));
    if (::ReadFile(s.handle, data, n, &got, &at) == 0)
        return ::GetLastError() == ERROR_HANDLE_EOF ? 0 : -1;
    return got;
}

long long write_at(int handle, const std::uint8_t* data, std::size_t size,
                   std::uint64_t offset) noexcept {
    const Slot s = get(handle);
    OVERLAPPED at{};
    at.Offset = static_cast<DWORD>(offset & 0xFFFFFFFFU);
    at.OffsetHigh = static_cast<DWORD>(offset >> 32);
    DWORD done = 0;
    const auto n = static_cast<DWORD>(std::min<std::size_t>(size, 1U << 30));
    if (::WriteFile(s.handle, data, n, &done, &at) == 0) return -1;
    return done;
}

bool truncate(int handle, std::uint64_t size) noexcept {
    const Slot s = get(handle);
    FILE_END_OF_FILE_INFO end{};
    end.EndOfFile.QuadPart = static_cast<LONGLONG>(size);
    return ::SetFileInformationByHandle(s.handle, FileEndOfFileInfo, &end, sizeof end) != 0;
}

bool sync(int handle) noexcept {
    const Slot s = get(handle);
    BY_HANDLE_FILE_INFORMATION i{};
    if (::GetFileInformationByHandle(s.handle, &i) == 0) return false;
    if ((i.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY) != 0) return true;
    return ::FlushFileBuffers(s.handle) != 0;
}

bool set_mtime(int handle, std::int64_t mtime) noexcept {
    const Slot s = get(handle);
    const FILETIME t = filetime_of(mtime);
    return ::SetFileTime(s.handle, nullptr, &t, &t) != 0;
}

bool set_mtime_at(int dir, const std::string& name, std::int64_t mtime) noexcept {
    try {
        HANDLE h = open_checked(child(dir, name), FILE_WRITE_ATTRIBUTES, share_all, OPEN_EXISTING,
                                Want::any);
        if (h == INVALID_HANDLE_VALUE) return false;
        const FILETIME t = filetime_of(mtime);
        const bool ok = ::SetFileTime(h, nullptr, &t, &t) != 0;
        ::CloseHandle(h);
        return ok;
    } catch (...) {
        return false;
    }
}

std::filesystem::path make_temp_directory(std::error_code& error) {
    const auto base = std::filesystem::temp_directory_path(error);
    if (error) return {};
    std::random_device random;
    for (int attempt = 0; attempt < 100; ++attempt) {
        auto dir = base / ("finsd-files-" + std::to_string(process_id()) + "-" +
                           std::to_string(random() & 0xFFFFFFU));
        if (std::filesystem::create_directory(dir, error)) return dir;
        if (error) return {};
    }
    error = std::make_error_code(std::errc::file_exists);
    return {};
}

unsigned process_id() noexcept {
    return static_cast<unsigned>(::GetCurrentProcessId());
}

}  // namespace fins::plc::host
#endif
