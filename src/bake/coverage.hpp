// Step 1 of the baker (internal, not installed): which texels the triangles' lightmap UVs cover,
// exactly, and each covered texel's sample point (bake.hpp, compute_lightmap_samples).
#pragma once

#include "hemilight/bake.hpp"

#include <cstdint>
#include <vector>

namespace hemilight::bake_detail {

// Twice the signed area of (a, b, c) in double.
inline double cross2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Step 1 for the covered texels only (the baker's own form of lightmap_samples): one entry per
// texel with coverage > 0, in texel order, each field as lightmap_samples defines it. Memory: a
// 4-byte slot per texel while it is computed, then about 80 bytes per covered texel.
struct sparse_samples {
  int width = 0, height = 0;
  std::vector<std::size_t> texel;  // texel index (row-major), increasing
  std::vector<float> coverage;
  std::vector<std::uint32_t> owner, sample_triangle;
  std::vector<glm::vec2> centroid;
  std::vector<glm::vec3> position, normal, tangent, bitangent;
  std::vector<float> texel_world_size;
  std::size_t overlapping_texels = 0;
  // Triangles that cover nothing (bake_stats' fields of the same names; the first in scene_desc
  // numbering of the input).
  std::size_t degenerate_triangles = 0, no_uv_area_triangles = 0;
  std::size_t first_no_uv_area_triangle = bake_stats::no_index;

  std::size_t size() const { return texel.size(); }
};

// compute_lightmap_samples (bake.hpp) for the covered texels only, of an input checked by
// check_input with its UVs clamped (clamp_lightmap_uvs). A triangle with 3D area but no UV area
// throws error(invalid_argument) with `strict` (named for `who`), else it is counted. Throws
// error(out_of_memory) beyond 2^32 - 1 covered texels. Cost: two clips per (triangle, texel of
// its bounding box).
sparse_samples compute_sparse_samples(const bake_input& input, int width, int height, bool strict, const char* who);

}  // namespace hemilight::bake_detail
