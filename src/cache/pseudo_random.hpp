// The cache's fixed pseudo-random orders (internal, not installed): a 64-bit mix for hashing
// (the placement's order of points, the sampler's roll angle) and the order of placement.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hemilight::cache_detail {

// 64-bit mix (splitmix64 finaliser): a fixed pseudo-random order of the points.
inline std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// The points 0..count-1 sorted by mix(i) (a bijection, so no two keys are equal): the fixed
// pseudo-random order of placement. Cost: O(count), four radix passes.
std::vector<std::uint32_t> pseudo_random_order(std::size_t count);

}  // namespace hemilight::cache_detail
