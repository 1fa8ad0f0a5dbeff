// cache_irradiance's input checks (internal, not installed); validate_cache_options is public
// (cache.hpp).
#pragma once

#include "hemilight/cache.hpp"

#include <cstddef>

namespace hemilight::cache_detail {

// Throws error(invalid_argument), naming the first bad input in cache_irradiance's terms: count
// 0, NULL arrays, a position not finite or beyond max_coordinate, a normal whose length is not 1
// within 1e-3, points spanning more than max_point_extent, options out of range
// (validate_cache_options). Cost: O(count).
void validate_cache_input(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const cache_options& o);

}  // namespace hemilight::cache_detail
