// Internal (not installed): the 64-bit mix behind every fixed pseudo-random order of the library
// (the cache's order of points, the sampler's roll angle).
#pragma once

#include <cstdint>

namespace hemilight::core_detail {

// 64-bit mix (splitmix64's finaliser): a bijection of the 64-bit integers that scatters nearby
// inputs. Cost: O(1).
inline std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace hemilight::core_detail
