// finsd's [memory] typed values: { TYPE = value } or { TYPE = [values] } turned into the
// words of each value in Omron's order (fins/values.hpp, as `fins write --as TYPE`):
// int16 uint16 int32 uint32 float double bcd (one word, 0-9999) bcd32 (two words)
// string (2 characters a word). Parsing only; config.cpp names the entry on error.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <toml++/toml.h>
#include <tl/expected.hpp>

namespace fins::cli::finsd {

struct TypedValueError {
    std::string path_suffix;  // "" (the entry) or ".TYPE" (one of its values)
    std::string message;
};

tl::expected<std::vector<std::uint32_t>, TypedValueError> typed_words(const toml::table& t);

}  // namespace fins::cli::finsd
