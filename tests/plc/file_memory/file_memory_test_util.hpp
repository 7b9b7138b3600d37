// What the file memory tests need of the host, on Linux and on Windows (wine): a fresh
// temporary directory, a file's modification time, the process's open handles, and a
// symlink where the platform lets a test make one.
#pragma once

#ifdef _WIN32
#include <windows.h>
#else
#include <sys/stat.h>
#include <unistd.h>
#endif

#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <system_error>

namespace fins::plc::test {

// A new empty directory under the temp directory, named `prefix`-something.
inline std::filesystem::path make_temp_dir(const std::string& prefix) {
    std::random_device random;
    const auto base = std::filesystem::temp_directory_path();
    for (int attempt = 0; attempt < 100; ++attempt) {
        auto dir = base / (prefix + "-" + std::to_string(random() & 0xFFFFFFU));
        if (std::filesystem::create_directory(dir)) return dir;
    }
    throw std::filesystem::filesystem_error("no temp directory", std::error_code{});
}

// Removes `dir` when it goes: declared before the FileMemory using it, it runs after the
// FileMemory closed its directories (Windows removes no directory held open).
struct RemoveAll {
    std::filesystem::path dir;
    RemoveAll() = default;
    RemoveAll(const RemoveAll&) = delete;
    RemoveAll& operator=(const RemoveAll&) = delete;
    ~RemoveAll() {
        std::error_code ec;
        if (!dir.empty()) std::filesystem::remove_all(dir, ec);
    }
};

// Seconds since 1970 of the file's last write (-1: cannot tell).
inline std::int64_t mtime_of(const std::filesystem::path& file) {
#ifdef _WIN32
    WIN32_FILE_ATTRIBUTE_DATA data{};
    if (::GetFileAttributesExW(file.c_str(), GetFileExInfoStandard, &data) == 0) return -1;
    const auto ticks = (std::uint64_t{data.ftLastWriteTime.dwHighDateTime} << 32) |
                       data.ftLastWriteTime.dwLowDateTime;
    return static_cast<std::int64_t>(ticks / 10'000'000) - 11644473600LL;
#else
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0) return -1;
    return st.st_mtime;
#endif
}

// Descriptors (Linux) or handles (Windows) the process holds.
inline std::size_t open_handles() {
#ifdef _WIN32
    DWORD n = 0;
    ::GetProcessHandleCount(::GetCurrentProcess(), &n);
    return n;
#else
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/fd"))
        ++n;
    return n;
#endif
}

// A symlink `link` -> `target`; false where the host refuses to make one (Windows
// without the privilege), so the caller can skip rather than fail.
inline bool make_symlink(const std::filesystem::path& target, const std::filesystem::path& link,
                         bool directory) {
    std::error_code ec;
    if (directory)
        std::filesystem::create_directory_symlink(target, link, ec);
    else
        std::filesystem::create_symlink(target, link, ec);
    return !ec;
}

}  // namespace fins::plc::test
