#include "bridge/cluster/rendezvous.hpp"

namespace fins::bridge::cluster {
namespace {

constexpr std::uint64_t fnv_offset = 0xcbf29ce484222325ULL;
constexpr std::uint64_t fnv_prime = 0x100000001b3ULL;

constexpr std::uint64_t fnv1a(std::uint64_t h, std::string_view s) noexcept {
    for (const char c : s) {
        h ^= static_cast<unsigned char>(c);
        h *= fnv_prime;
    }
    return h;
}

constexpr std::uint64_t mix(std::uint64_t z) noexcept {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

}  // namespace

std::uint64_t rendezvous_weight(std::string_view member, std::string_view plc) noexcept {
    // The separator byte 0 keeps ("ab","c") and ("a","bc") apart (names cannot contain it).
    std::uint64_t h = fnv1a(fnv_offset, member);
    h ^= 0;
    h *= fnv_prime;
    return mix(fnv1a(h, plc));
}

std::size_t rendezvous_owner(std::span<const std::string> members, std::string_view plc) noexcept {
    std::size_t best = members.size();
    std::uint64_t best_weight = 0;
    for (std::size_t i = 0; i < members.size(); ++i) {
        const auto w = rendezvous_weight(members[i], plc);
        if (best == members.size() || w > best_weight ||
            (w == best_weight && members[i] < members[best])) {
            best = i;
            best_weight = w;
        }
    }
    return best;
}

}  // namespace fins::bridge::cluster
