// The cache's fixed pseudo-random order of placement (internal, not installed).
#pragma once

#include "../core/hash.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hemilight::cache_detail {

using core_detail::mix;

// The points 0..count-1 sorted by mix(i) (a bijection, so no two keys are equal): the fixed
// pseudo-random order of placement. Cost: O(count), four radix passes.
std::vector<std::uint32_t> pseudo_random_order(std::size_t count);

}  // namespace hemilight::cache_detail
