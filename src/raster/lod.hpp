// Internal to the rasterizer (not installed): level-of-detail proxies of the scene's BVH nodes
// (raster_options::lod_texels; docs/raster.md, "Level of detail").
#pragma once

#include "hemilight/scene.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace hemilight::raster_detail {

// Per BVH node, a simplified stand-in for the triangles below it: node i's proxy is
// triangles[first[i], first[i] + count[i]) (count 0: none). A leaf's proxy simplifies its
// triangles, an inner node's the union of its children's proxies, each to about half, within
// each shade (emission and sidedness: the proxy keeps what the rasterizer draws); vertices are the
// scene's own (lightmap UVs stay valid), simplified with meshoptimizer.
struct lod_proxies {
  std::vector<std::uint32_t> first, count;
  // World positions; index = a scene triangle of the same emission and sidedness (its material).
  std::vector<scene::triangle> triangles;
  std::vector<std::array<std::uint32_t, 3>> vertices;  // the scene vertex indices of each (UVs)
};

// The proxies of `s`, built on the first call (thread-safe; kept with the scene, freed with it).
// Cost: O(T log T) once for T drawable triangles (meshoptimizer's simplifier over each node's
// proxy input; about as many proxy triangles as scene triangles in all); memory about 52 bytes
// per proxy triangle. Throws std::bad_alloc.
const lod_proxies& lod_proxies_of(const scene& s);

}  // namespace hemilight::raster_detail
