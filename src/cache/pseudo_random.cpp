// pseudo_random_order (pseudo_random.hpp).
#include "pseudo_random.hpp"

#include <algorithm>

namespace hemilight::cache_detail {

// The points 0..count-1 sorted by mix(i) (a bijection, so no two keys are equal): the fixed
// pseudo-random order of placement. A least-significant-digit radix sort, four passes of 16 bits.
std::vector<std::uint32_t> pseudo_random_order(std::size_t count) {
  std::vector<std::uint64_t> key(count), key_tmp(count);
  std::vector<std::uint32_t> idx(count), idx_tmp(count);
  for (std::size_t i = 0; i < count; ++i) {
    key[i] = mix(i);
    idx[i] = static_cast<std::uint32_t>(i);
  }
  std::vector<std::uint32_t> start(1u << 16);
  for (int shift = 0; shift < 64; shift += 16) {
    std::fill(start.begin(), start.end(), 0u);
    for (std::uint64_t k : key) ++start[(k >> shift) & 0xffffu];
    std::uint32_t sum = 0;
    for (std::uint32_t& c : start) {
      const std::uint32_t n = c;
      c = sum;
      sum += n;
    }
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint32_t at = start[(key[i] >> shift) & 0xffffu]++;
      key_tmp[at] = key[i];
      idx_tmp[at] = idx[i];
    }
    key.swap(key_tmp);
    idx.swap(idx_tmp);
  }
  return idx;
}

}  // namespace hemilight::cache_detail
