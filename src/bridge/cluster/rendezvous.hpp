// Rendezvous (highest random weight) hashing: the owner of a PLC is the live member whose
// weight(member, plc) is highest. Every instance computes the same answer from the same member
// list, with no coordination; when a member joins it takes only the PLCs it now weighs
// highest for, when one dies only its PLCs move (each to its own second choice), so about
// 1/n of the PLCs move either way.
//
// The weight is our own 64-bit hash (FNV-1a over both names, then the SplitMix64 finaliser),
// fixed here and not std::hash: instances built by different compilers must agree.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace fins::bridge::cluster {

std::uint64_t rendezvous_weight(std::string_view member, std::string_view plc) noexcept;

// The index in members of the owner of plc, or members.size() when members is empty. Ties
// (equal weights: practically never) go to the smaller name, so the answer is still unique.
std::size_t rendezvous_owner(std::span<const std::string> members, std::string_view plc) noexcept;

}  // namespace fins::bridge::cluster
