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
// Every drawable triangle (non-zero area) is hit from either side: materials, one-sidedness and
// emission play no part (lights are occluded by the back of a wall as by its front). Debian builds
// Embree without backface culling; should an Embree with culling be installed, the build below
// fails (status unsupported) rather than miss back faces (tests/test_rays.cpp checks the device).
//
// Acceleration structure: an Embree scene (one triangle geometry, primitive i = scene::triangles()[i],
// built with RTC_SCENE_FLAG_ROBUST: robust traversal and Embree's Pluecker triangle test,
// watertight along shared edges, below; RTC_BUILD_QUALITY_MEDIUM), built once per scene on its first query or prepare_rays()
// call (std::call_once: thread-safe; the other threads wait), so scenes that never trace a ray pay
// nothing. One RTCDevice for the whole process, made on first use (thread-safe), released at exit.
// Embree builds with its own TBB threads (all cores). Build (prepare_rays, wall time, two cores of
// a shared AMD EPYC server; benchmarks/bench_rays.cpp rays/build): hexagon room at tessellation 3
// (1,062 triangles) 0.29 ms, open pavilion (708) 0.20 ms, Cornell box (32) 14 us; a 1M-triangle
// heightfield about 0.5 s. Memory (Embree's memory monitor: its copy of the vertices and indices
// plus the BVH and its leaves' triangles): 95 bytes per triangle (hexagon room), 113 (open
// pavilion), 79 (1M heightfield), besides the scene's own ~140. RTC_BUILD_QUALITY_HIGH measured
// the same build time, memory and ray speed on these scenes (this Embree applies no spatial splits
// to robust triangles), so the build uses MEDIUM.
//
// Watertightness: Embree's robust test is watertight along shared edges (no ray aimed at an edge
// point of a closed grid slips through: tests/test_rays.cpp) but evaluates its edge functions in
// float with a tolerance of one ulp of their sum, so a ray aimed exactly at a shared vertex can
// slip through (about 1% of such rays with its AVX2 kernels). A ray passes within rounding (~1e-7
// of its distance from the origin) of a given vertex with a chance of order 1e-14 for rays spread
// over the scene: shadows and bakes are not affected in practice.
// The fallback traversal (below) is watertight at vertices too (exact edge functions in double).
//
// Errors: Embree can fail to make its device (unsupported CPU) or run out of memory building. The
// queries are noexcept and used inside parallel loops, so a failed build is not thrown from them:
// it is kept in the scene (never retried) and the queries then answer through the fallback, a
// traversal of the scene's own BVH (the rasterizer's, 32-triangle leaves; src/rays_bvh.cpp): the
// same contract (Woop, Benthin and Wald's watertight test, tested against the same reference),
// 3x to 14x slower. Call prepare_rays() first to get the failure as a hemilight::error instead.
//
// Thread safety: any number of threads may query the same scene at once; the queries allocate
// nothing after the build.
//
// Cost (one core of a shared AMD EPYC server; benchmarks/bench_rays.cpp, docs/lights.md): shadow
// rays 75-120 ns (8.5 M/s in the Cornell box, 13 M/s in the hexagon room and the open pavilion),
// closest hit 85-130 ns; 85-90% of a bare rtcOccluded1 / rtcIntersect1 on the same robust Embree
// scene (our per-call overhead: the input checks, the ray set-up and an acquire load for the lazy
// build, 7-16 ns). The fallback: 1.2-5.2 M shadow rays/s.

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
  std::uint32_t drawable = 0;    ///< its index in scene::triangles() (BVH order)
  bool front_face = false;       ///< the ray arrives on the front side (direction . normal < 0)
};

/// Builds the scene's Embree scene now if it is not built yet (the queries below would build it on
/// their first call), so that its cost is paid here and its failure is reported.
/// Errors (hemilight::error): out_of_memory (Embree ran out of memory), unsupported (Embree cannot
/// run on this CPU, or was built with backface culling), internal (any other Embree error); the
/// message names the Embree error. After a failure the queries still answer, through the
/// fallback traversal (top of this header). Thread-safe; idempotent (a failure is not retried).
/// Cost: the build (top of this header); O(1) once built.
void prepare_rays(const scene& s);

/// Any-hit query: true if some drawable triangle of `s` is hit at 0 < t < t_max by
/// origin + t direction. Stops at the first hit found (not the nearest).
/// A zero or non-finite direction, a non-finite origin, a NaN t_max or t_max <= 0 returns false.
/// Cost: see the top of this header (the first query of a scene builds its Embree scene);
/// thread-safe, no allocation after the build.
bool occluded(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept;

/// Batch any-hit query: out[i] = occluded(s, origin, directions[i], t_max[i]) for i < count, the
/// rays sharing one origin (a shadow-ray bundle towards a light). Same contract per ray as
/// occluded() (0 < t < t_max[i] exclusive, the same tfar margin; an invalid ray, or a non-finite
/// origin, gives false without tracing); count 0 does nothing (the pointers may then be null).
/// Through Embree the rays go as packets of 8 (rtcOccluded8; a last packet of at most 4 as
/// rtcOccluded4) with the invalid rays masked off; the fallback traces them one by one. Answers
/// equal occluded()'s except, rarely, for rays within rounding of an edge (the packet kernels
/// round differently). Cost: O(count) rays, cheaper per ray than occluded() for coherent bundles:
/// the direct-light stage of the 654^2 hexagon room with seven lights (soft lights' 12 probes as
/// one call; benchmarks/sweep_lights.cpp --only direct, two shared cores, paired medians) took
/// 1.11-1.18 s against 1.21-1.33 s with one occluded() per probe. Thread-safe, no allocation.
void occluded_many(const scene& s, const glm::vec3& origin, const glm::vec3* directions, const float* t_max,
                   std::size_t count, bool* out) noexcept;

/// Closest-hit query: the nearest drawable triangle hit at 0 < t < t_max, written to `hit`
/// (untouched when there is none). Returns whether one was found. Triangles hit at exactly the
/// same t (shared edges, coplanar overlaps): one of them, Embree's choice. front_face from the
/// sign of direction . Embree's geometric normal ((v1 - v0) x (v2 - v0) up to scale).
/// Inputs and cost as occluded() (no early exit: about 1.5x its time).
bool intersect(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max, ray_hit& hit) noexcept;

}  // namespace hemilight
