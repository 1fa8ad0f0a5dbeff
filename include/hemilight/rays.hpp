// hemilight/rays.hpp — ray queries against a scene's triangles: any-hit (shadow rays) and
// closest-hit, over the scene's own BVH (scene::bvh(), scene::triangles()).
//
// A ray is origin + t direction. `direction` need not be unit length: t is measured in units of
// |direction|, so a shadow ray from x to a point y is (x, y - x) with t_max = 1. A query reports
// triangles hit at 0 < t < t_max (both bounds exclusive); t_max may be +inf.
//
// Every drawable triangle (non-zero area) is hit from either side: materials, one-sidedness and
// emission play no part (lights are occluded by the back of a wall as by its front).
//
// Triangle test: the watertight test of Woop, Benthin and Wald (2013, "Watertight ray/triangle
// intersection", JCGT 2(1)): the vertices are translated to the ray origin and sheared so that the
// ray runs along the z axis, and the three 2D edge functions are evaluated in float; when one of
// them is exactly 0, the three are evaluated again in double (the products of two floats are
// exact there, so the sign is exact). A shared edge gives the two triangles edge functions of
// opposite sign, bit for bit (src/rays.cpp is compiled without fused multiply-adds for this), so a
// ray through a shared edge or vertex of a closed mesh hits at least one of its triangles: no
// cracks. No epsilon anywhere in the triangle test.
//
// Boxes: the slab test with a precomputed reciprocal direction (components of |d| < 1e-30 are
// treated as 1e-30 with their sign, so rays parallel to a slab never give NaN) and the far
// distance scaled by 1 + 2 gamma(3) (Ize 2013, "Robust BVH ray traversal"), so rounding never
// culls a box the ray touches. Traversal is ordered (the nearer child first) with a fixed stack
// of 64 entries (the BVH's depth is at most 27: it splits at multiples of 32 triangles near the
// median, so depth <= ceil(log2(2^31 / 32)) + 1).
//
// Leaves (up to scene::max_leaf_triangles = 32 triangles) are tested in a loop the compiler
// vectorises (#pragma omp simd; four lanes with SSE2) over the per-coordinate arrays
// (scene::vertex_coordinates), in groups of eight (lanes past the leaf's end are masked).
//
// Thread safety: the queries are free functions of a const scene with no state of their own (no
// caches, no counters, nothing static); any number of threads may query the
// same scene at once. No allocation.
//
// Cost (one core of a shared AMD EPYC server, SSE2; benchmarks/bench_rays.cpp, docs/lights.md):
// O(log T) node visits plus up to 32 triangle tests per leaf whose box the ray crosses. Shadow
// rays: about 0.2 us in the Cornell box (5.3 M/s), 0.5 us in the open pavilion (2.1 M/s), 0.9 us
// in the hexagon room at tessellation 3 (1.1 M/s: rays inside a room cross the boxes of most of
// its 32-triangle leaves). Embree's rtcOccluded1 on the same rays is 3x to 14x faster (its BVH
// has small leaves built for rays; this one is the rasterizer's).

#pragma once

#include "hemilight/scene.hpp"

#include <glm/glm.hpp>

#include <cstdint>

namespace hemilight {

/// What a closest-hit query found.
struct ray_hit {
  float distance = 0.0f;         ///< t of the hit (units of |direction|), in (0, t_max)
  std::uint32_t triangle = 0;    ///< the triangle's number in the scene_desc
  std::uint32_t drawable = 0;    ///< its index in scene::triangles() (BVH order)
  bool front_face = false;       ///< the ray arrives on the front side (direction . normal < 0)
};

/// Any-hit query: true if some drawable triangle of `s` is hit at 0 < t < t_max by
/// origin + t direction. Stops at the first hit found (not the nearest).
/// Preconditions (not checked beyond what is stated): origin finite; t_max > 0 or +inf.
/// A zero or non-finite direction, a NaN t_max or t_max <= 0 returns false. Cost: see the top
/// of this header; thread-safe, no allocation.
bool occluded(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept;

/// Closest-hit query: the nearest drawable triangle hit at 0 < t < t_max, written to `hit`
/// (untouched when there is none). Returns whether one was found. Triangles hit at exactly the
/// same t: the first in BVH order among those in the first leaf that reaches that t (deterministic
/// for a given scene and ray). Preconditions and cost as occluded() (it visits more nodes: no
/// early exit, only the pruning of boxes farther than the nearest hit so far).
bool intersect(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max, ray_hit& hit) noexcept;

}  // namespace hemilight
