#include "config/text_file.hpp"

#include <algorithm>
#include <array>
#include <fstream>

#include <fmt/format.h>

namespace fins::config {

tl::expected<std::string, std::string> read_text_file(const std::filesystem::path& path,
                                                      std::size_t limit) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return tl::unexpected(fmt::format("{}: cannot read the file", path.string()));
    std::string text;
    std::array<char, 64 * 1024> chunk{};
    // Up to one byte past the limit: that byte says the file is larger.
    while (text.size() <= limit) {
        const std::size_t want = std::min(chunk.size(), limit + 1 - text.size());
        in.read(chunk.data(), static_cast<std::streamsize>(want));
        const auto got = in.gcount();
        if (got <= 0) break;
        text.append(chunk.data(), static_cast<std::size_t>(got));
    }
    if (in.bad()) return tl::unexpected(fmt::format("{}: cannot read the file", path.string()));
    if (text.size() > limit) {
        const std::string size = limit >= (std::size_t{1} << 20)
                                     ? fmt::format("{} MiB", limit >> 20)
                                     : fmt::format("{} bytes", limit);
        return tl::unexpected(
            fmt::format("{}: larger than {}: not a configuration file", path.string(), size));
    }
    return text;
}

}  // namespace fins::config
