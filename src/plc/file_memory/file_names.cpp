// The CPU Unit's name and path rules for plc::FileMemory (frames-serial-files 4.1):
// pure text checks, no host access, the one place for them on Linux and Windows. What
// Windows treats specially never passes: ':' (streams), '\\' and '/', spaces, a trailing
// dot (an extension is 1..3 characters after the only dot), and device names.
#include <algorithm>
#include <array>

#include "plc/file_memory/file_memory.hpp"

namespace fins::plc {

namespace {

bool allowed(char c) noexcept {
    if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')) return true;
    return std::string_view("!&$#'{}-^()_~").find(c) != std::string_view::npos;
}

char upper(char c) noexcept {
    return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
}

// Names DOS and Windows give to devices, whatever the extension: CON, PRN, AUX, NUL,
// CLOCK$, CONFIG$, CONIN$, CONOUT$, COM0..COM9, LPT0..LPT9. Refused on every host, so
// that a card written under Linux is one Windows can hold (docs/file-memory.md).
bool device_name(std::string_view base) noexcept {
    static constexpr std::array<std::string_view, 8> names{
        "CON", "PRN", "AUX", "NUL", "CLOCK$", "CONFIG$", "CONIN$", "CONOUT$"};
    if (std::find(names.begin(), names.end(), base) != names.end()) return true;
    return base.size() == 4 && (base.starts_with("COM") || base.starts_with("LPT")) &&
           base[3] >= '0' && base[3] <= '9';
}

}  // namespace

// ---- names ----

std::optional<std::string> FileMemory::canonical_name(std::string_view text) {
    const auto dot = text.find('.');
    const auto base = text.substr(0, dot);
    const auto ext = dot == std::string_view::npos ? std::string_view{} : text.substr(dot + 1);
    if (base.empty() || base.size() > 8 || ext.size() > 3) return std::nullopt;
    if (dot != std::string_view::npos && ext.empty()) return std::nullopt;
    if (base.starts_with("~~")) return std::nullopt;
    std::string out;
    for (const char c : base) {
        if (!allowed(c)) return std::nullopt;
        out.push_back(upper(c));
    }
    if (device_name(out)) return std::nullopt;
    if (!ext.empty()) out.push_back('.');
    for (const char c : ext) {
        if (!allowed(c)) return std::nullopt;
        out.push_back(upper(c));
    }
    return out;
}

std::optional<std::string> FileMemory::canonical_name(const FileName& name) {
    const auto& b = name.bytes;
    if (b[0] == 0x00 || b[0] == 0xE5) return std::nullopt;
    // Padding: the name, then only 20 hex; "." (or 20 with an all-20 extension).
    std::string text;
    std::size_t i = 0;
    for (; i < 8 && b[i] != 0x20; ++i)
        text.push_back(static_cast<char>(b[i]));
    for (; i < 8; ++i)
        if (b[i] != 0x20) return std::nullopt;
    if (b[8] == '.') {
        text.push_back('.');
        for (i = 9; i < 12 && b[i] != 0x20; ++i)
            text.push_back(static_cast<char>(b[i]));
        for (; i < 12; ++i)
            if (b[i] != 0x20) return std::nullopt;
    } else if (b[8] != 0x20 || b[9] != 0x20 || b[10] != 0x20 || b[11] != 0x20) {
        return std::nullopt;
    }
    return canonical_name(text);
}

// Visible to FINS: a canonical (already upper-case) valid name.
bool FileMemory::visible(std::string_view name) {
    const auto c = canonical_name(name);
    return c && *c == name;
}

// "\A\B" -> {"A", "B"}; "" and "\" -> root.
std::optional<std::vector<std::string>> FileMemory::parse_directory(std::string_view path) {
    std::vector<std::string> out;
    if (path.empty() || path == "\\") return out;
    if (path.size() > max_directory_path || path.front() != '\\' || path.back() == '\\')
        return std::nullopt;
    std::size_t start = 1;
    while (start <= path.size()) {
        const auto end = std::min(path.find('\\', start), path.size());
        const auto name = canonical_name(path.substr(start, end - start));
        if (!name || out.size() == max_file_directories) return std::nullopt;
        out.push_back(*name);
        start = end + 1;
    }
    return out;
}
}  // namespace fins::plc
