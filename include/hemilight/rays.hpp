// hemilight/rays.hpp — ray queries against a scene's triangles: any-hit (shadow rays) and
// closest-hit, through Embree 3 (Debian's libembree-dev) over the scene's drawable triangles.
//
// A ray is origin + t direction. `direction` need not be unit length: t is measured in units of
// |direction|, so a shadow ray from x to a point y is (x, y - x) with t_max = 1. A query reports
// triangles hit at 0 < t < t_max (both bounds exclusive); t_max may be +inf. Embree accepts
// tnear <= t <= tfar (both inclusive) on its float t = rcp(den) * T, a few ulps from the exact t;
// the queries pass tnear = the smallest positive float (t > 0) and tfar = t_max (1 - 2^-20)
// (+inf stays +inf): a triangle at exactly t_max (the end of a shadow ray on a light) is never
// hit, at the price of hits in the last 1e-6 of the segment. Zero or non-finite directions,
// non-finite origins, NaN or non-positive t_max are answered "no hit" here, before Embree sees them.
//
// Every drawable triangle (non-zero area) is hit from either side: one-sidedness and emission play
// no part (lights are occluded by the back of a wall as by its front). See-through triangles
// (scene.hpp's surface_opacity): an alpha-tested one is hit only where it is present
// (scene::alpha_present at the hit point, decided by an Embree filter function); a translucent one
// is a surface to occluded(), occluded_many() and intersect(), and multiplies its transmittance
// into transmittance() (the shadow rays of lights.hpp). Should an
// Embree built with backface culling be installed, the build fails (status unsupported) rather
// than miss back faces.
//
// Acceleration structure: a robust Embree scene (primitive i = scene::triangles()[i]), built once
// per scene on its first query or prepare_rays() call (std::call_once: thread-safe; the other
// threads wait), so scenes that never trace a ray pay nothing; one Embree device per process.
// Watertight along shared edges; a ray aimed exactly at a shared vertex can slip through, which
// rays spread over a scene do with a chance of order 1e-14 per vertex. Build time, memory and
// ray throughput: docs/lights.md, "Ray queries".
//
// Errors: Embree can fail to make its device (unsupported CPU) or run out of memory building. The
// queries are noexcept and used inside parallel loops, so a failed build is not thrown from them:
// it is kept in the scene (never retried) and the queries then answer through the fallback, a
// traversal of the scene's own BVH with the same contract (watertight at vertices too), slower.
// Call prepare_rays() first to get the failure as a hemilight::error instead.
//
// Thread safety: any number of threads may query the same scene at once; the queries allocate
// nothing after the build.

#pragma once

#include "hemilight/scene.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>

namespace hemilight {

/// What a closest-hit query found.
struct ray_hit {
  float distance = 0.0f;         ///< t of the hit (units of |direction|), in (0, t_max)
  std::uint32_t triangle = 0;    ///< the triangle's number in the scene_desc
  /// Its index in scene::triangles() (BVH order), or for a see-through triangle
  /// scene::triangles().size() + its index in scene::see_through_triangles().
  std::uint32_t drawable = 0;
  bool front_face = false;       ///< the ray arrives on the front side (direction . normal < 0)
};

/// Builds the scene's Embree scene now if it is not built yet (the queries below would build it on
/// their first call), so that its cost is paid here and its failure is reported.
/// Errors (hemilight::error): out_of_memory (Embree ran out of memory), unsupported (Embree cannot
/// run on this CPU, or was built with backface culling), internal (any other Embree error); the
/// message names the Embree error. After a failure the queries still answer, through the
/// fallback traversal (top of this header). Thread-safe; idempotent (a failure is not retried).
/// Cost: the build, O(T log T) for T triangles; O(1) once built.
void prepare_rays(const scene& s);

/// Any-hit query: true if some drawable triangle of `s` is hit at 0 < t < t_max by
/// origin + t direction. Stops at the first hit found (not the nearest).
/// A zero or non-finite direction, a non-finite origin, a NaN t_max or t_max <= 0 returns false.
/// Cost: one BVH traversal (the first query of a scene builds its Embree scene); thread-safe, no
/// allocation after the build.
bool occluded(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept;

/// Batch any-hit query: out[i] = occluded(s, origin, directions[i], t_max[i]) for i < count, the
/// rays sharing one origin (a shadow-ray bundle towards a light). Same contract per ray as
/// occluded() (0 < t < t_max[i] exclusive, the same tfar margin; an invalid ray, or a non-finite
/// origin, gives false without tracing); count 0 does nothing (the pointers may then be null).
/// Through Embree the rays go as packets of 8 (rtcOccluded8; a last packet of at most 4 as
/// rtcOccluded4) with the invalid rays masked off; the fallback traces them one by one. Answers
/// equal occluded()'s except, rarely, for rays within rounding of an edge (the packet kernels
/// round differently). Cost: O(count) rays, cheaper per ray than occluded() for coherent bundles
/// (docs/lights.md). Thread-safe, no allocation.
void occluded_many(const scene& s, const glm::vec3& origin, const glm::vec3* directions, const float* t_max,
                   std::size_t count, bool* out) noexcept;

/// Transmittance query (shadow rays through see-through surfaces): per channel, the fraction of
/// light that passes from origin to origin + t_max direction: 0 if an opaque triangle, or an
/// alpha-tested one where present, is hit at 0 < t < t_max; otherwise the product of the
/// transmittances of the translucent triangles hit (each once), (1, 1, 1) when nothing is. Inputs
/// as occluded() (an invalid query gives (1, 1, 1)). Equals 1 - occluded() in every channel for a
/// scene without see-through triangles. Cost: one traversal that does not stop at translucent hits
/// (an Embree filter function multiplies them in; at most 16 distinct panes are remembered per ray,
/// a pane hit again beyond that counts twice); thread-safe, no allocation.
glm::vec3 transmittance(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept;

/// Closest-hit query: the nearest drawable triangle hit at 0 < t < t_max, written to `hit`
/// (untouched when there is none). Returns whether one was found. Triangles hit at exactly the
/// same t (shared edges, coplanar overlaps): one of them, Embree's choice. front_face from the
/// sign of direction . Embree's geometric normal ((v1 - v0) x (v2 - v0) up to scale).
/// Inputs as occluded(); cost one BVH traversal without early exit.
bool intersect(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max, ray_hit& hit) noexcept;

}  // namespace hemilight
