// finsd's [memory] typed values: { TYPE = value } or { TYPE = [values] } turned into the
// words of each value in Omron's order (fins/values.hpp, as `fins write --as TYPE`).
// The types, their ranges and their words are src/typed's table (value_format.hpp, also
// the web API's and fins-bridge's): int16 uint16 int32 uint32 float double bcd (one word,
// 0-9999) bcd32 (two words) string (2 characters a word). Parsing only; the messages name
// the file, position and dotted key of the entry.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <toml++/toml.h>
#include <tl/expected.hpp>

#include "config/schema.hpp"
#include "finsd/config.hpp"

namespace fins::finsd {

struct TypedValueError {
    std::string path_suffix;  // "" (the entry) or ".TYPE" (one of its values)
    std::string message;
};

tl::expected<std::vector<std::uint32_t>, TypedValueError> typed_words(const toml::table& t);

// A table's entries in file order: [memory] entries are written in the order they are
// written down (later ones win where they overlap).
using config::in_file_order;

// One entry of a [memory] table (or of a [[plc]]'s memory table): `key` the address,
// `node` a value, an array of values or a { TYPE = ... } table. Errors read
// "SOURCE:LINE:COLUMN: PREFIX."KEY": complaint".
Expected<MemoryInit> memory_entry(const toml::key& key, const toml::node& node,
                                  std::string_view source, std::string_view prefix);

}  // namespace fins::finsd
