// A configuration file read whole, with a bound: finsd's and fins-bridge's TOML, a
// scenario file, a token file. A careless path (/dev/zero, /dev/urandom, a log that never
// ends, a FIFO nobody closes after writing gigabytes) must end in a message, not in a
// process that reads until the machine runs out of memory. 16 MiB is a thousand times the
// largest configuration a plant of 10,000 CPU Units needs with `repeat`.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include <tl/expected.hpp>

namespace fins::config {

inline constexpr std::size_t max_text_file = std::size_t{16} << 20;

// The file's bytes, or one of "PATH: cannot read the file" and "PATH: larger than N MiB:
// not a configuration file" (N = limit / 1 MiB, or "LIMIT bytes" below 1 MiB).
tl::expected<std::string, std::string> read_text_file(const std::filesystem::path& path,
                                                      std::size_t limit = max_text_file);

}  // namespace fins::config
