// Fuzzes the address parser: whatever parses must format to a string that parses back
// to the same address and formats identically, and every memory address it maps to
// must exist in the 5-2-2 table.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fins/address.hpp"

namespace {
void check(bool ok) {
    if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace fins;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto a = parse_address(text);
    if (!a) {
        check(a.error().category() == address_category());
        return 0;
    }
    const auto formatted = format_address(*a);
    auto again = parse_address(formatted);
    check(again.has_value() && *again == *a && format_address(*again) == formatted);
    for (auto access : {Access::natural, Access::word, Access::bit, Access::forced}) {
        if (auto m = to_memory_address(*a, access)) check(find_segment(m->area_code, m->word));
    }
    return 0;
}
