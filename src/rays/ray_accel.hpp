// Internal to hemilight (not installed): the scene's ray acceleration structure behind rays.hpp.
//
// scene (scene.hpp) holds a detail::lazy_slot (src/scene/scene_access.hpp, derived_kind::rays),
// empty until rays.cpp builds the Embree scene into it on the first ray query or prepare_rays()
// call.
// The tests (tests/test_rays.cpp) and bench_rays include this header for the hooks below.
#pragma once

#include "hemilight/rays.hpp"
#include "hemilight/scene.hpp"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

namespace hemilight {
namespace detail {

struct ray_accel;  // defined in rays.cpp

/// The fallback queries over the scene's own BVH (rays_bvh.cpp): rays.hpp's contract, without Embree.
/// rays.cpp uses them when the Embree scene could not be built; the tests run both.
bool occluded_bvh(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept;
bool intersect_bvh(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max,
                   ray_hit& hit) noexcept;

/// The see-through triangles' share of the fallback queries (see_through_rays.cpp): any present hit
/// (alpha-tested where present, translucent always); the product of the translucent hits'
/// transmittances, 0 at a present alpha-tested hit; the nearest present hit (hit.drawable =
/// triangles().size() + its index in see_through_triangles()). Brute force over those triangles.
bool see_through_occluded(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept;
glm::vec3 see_through_transmittance(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept;
bool see_through_closest(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max,
                         ray_hit& hit) noexcept;

/// Whether translucent hits at t_a on triangle a and t_b on triangle b are one crossing of one
/// surface (a ray through an edge that two of its triangles share): the same material, t within
/// 1e-5 relative. transmittance() counts such a pair once.
inline bool same_layer(const scene& s, std::uint32_t a, float t_a, std::uint32_t b, float t_b) noexcept {
  const material& ma = s.triangle_material(a);
  const material& mb = s.triangle_material(b);
  return ma.transmittance == mb.transmittance && ma.emission == mb.emission &&
         std::fabs(t_a - t_b) <= 1e-5f * std::max(std::fabs(t_a), std::fabs(t_b));
}

/// Whether the scene's queries go through Embree: builds the Embree scene first if it is not built
/// yet (as a query would) and returns false if that failed (the queries then use the fallback).
bool rays_use_embree(const scene& s) noexcept;

/// Bytes Embree's shared device holds now (its memory monitor: buffers, BVHs, build scratch), for
/// bench_rays' bytes-per-triangle figure. 0 before the device exists.
std::int64_t embree_device_bytes() noexcept;

/// Test hook: while set, building an Embree scene fails as if Embree ran out of memory (scenes
/// already built keep theirs; a scene whose build failed keeps the fallback). Tests only.
void fail_embree_builds_for_testing(bool fail) noexcept;

}  // namespace detail
}  // namespace hemilight
