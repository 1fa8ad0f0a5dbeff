// Dilation with blocked texels (internal, not installed); dilate itself is public (bake.hpp).
#pragma once

#include "hemilight/image_io.hpp"

#include <cstdint>
#include <vector>

namespace hemilight::bake_detail {

// dilate() with texels that are never filled (blocked[k] = 1, or null: none): the gaps between
// the pages of a scene bake, so that dilation stays inside each page.
// rings: as dilate's (-1: until nothing is left to fill). Returns the texels filled. Cost: O(texels
// + filled texels x 8).
std::size_t dilate_masked(image& img, std::vector<std::uint8_t>& filled, int rings, const std::uint8_t* blocked);

}  // namespace hemilight::bake_detail
