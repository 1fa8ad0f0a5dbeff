// hemilight/lights.hpp — analytic lights (sun, point, spot, rectangle) and their direct
// irradiance at a surface point, with shadows from shadow rays against the scene (rays.hpp).
//
// Lights are not geometry: hemicubes never see them and shadow rays never hit them, so an
// emissive triangle and a light are two separate sources (no double counting, nothing hides a
// light but the scene's triangles). Units as everywhere (docs/conventions.md): radiance
// W m^-2 sr^-1, irradiance E = integral of L cos(theta) d omega in W m^-2, no hidden 1/pi.
//
// The types (the fields a type does not use are ignored, but must still be finite):
//   directional  the sun. color = irradiance on a plane facing it (W/m^2); direction = direction
//                of travel of its light; radius = angular radius (rad, in [0, pi/2]; 0 = hard,
//                the sun is 0.00465). A disc of uniform radiance color / (pi sin^2(radius)).
//   point        color = intensity (W/sr); position; radius = sphere radius (m, >= 0; 0 = hard).
//                A sphere of uniform radiance color / (pi radius^2), so at distances where it is
//                fully above the horizon it gives exactly the irradiance of the point.
//   spot         as point, plus direction = axis and spot_inner <= spot_outer half-angles (rad,
//                outer <= pi/2). glTF KHR_lights_punctual's falloff: with cd = axis . (direction
//                from the light to the point),
//                    scale  = 1 / max(0.001, cos(spot_inner) - cos(spot_outer))
//                    offset = -cos(spot_outer) scale
//                    intensity factor = clamp(cd scale + offset, 0, 1)^2
//                (1 inside the inner cone, 0 outside the outer one, smooth between). With a
//                radius the factor is evaluated at the sphere's centre.
//   rect         a one-sided rectangle: position = centre; direction = normal of the emitting
//                side; tangent = direction of its width (made orthogonal to the normal: t - (t.n)n,
//                normalised); width and height (> 0, m) along t and b = n x t; color = radiance
//                (W/m^2/sr). Its corners are centre +- width/2 t +- height/2 b.
//
// Unoccluded irradiance at a point p with unit normal n (unoccluded_irradiance; the formulas:
// docs/lights.md, "Unoccluded irradiance"):
//   hard point, spot: I cos(theta) / d^2 (times the spot factor); 0 for d = 0. Hard sun: E cos(theta).
//   sphere or sun disc (a cone of half-angle a, sin a = r / d or the angular radius, of uniform
//     radiance L): fully above the horizon pi L sin^2(a) cos(theta), the hard light's value;
//     straddling it, the exact irradiance of the cone cut by the horizon (Snyder 1996); inside
//     the sphere (d <= r) pi L (1 + cos(theta)) / 2.
//   rect: 0 if p is not in front of the emitting side; otherwise Lambert's formula on the
//     rectangle clipped to p's upper half-space, in double. Exact where the light is visible.
//
// Shadows (direct_light): E = unoccluded E x visibility, visibility in [0, 1] from shadow rays
// (occluded(), rays.hpp; every triangle, either side) from p + offset n (direct_options) towards
// the light, stopping `offset` before the light's surface. Hard lights: one ray, visibility 0 or
// 1. Soft lights (radius > 0; rect always): the irradiance-weighted fraction of stratified
// samples over the light's extent, exact for a fully visible or fully blocked light; 8 outline
// probes and probe_samples samples first, continued to penumbra_samples where they disagree
// (docs/lights.md, "Visibility"). The samples depend only on the point, the normal and the
// light's index, never on threads or call order.
//
// Thread safety: light_set is immutable after construction; the functions below keep no state
// and allocate nothing, so any number of threads may evaluate the same lights at once.
#pragma once

#include "hemilight/rays.hpp"
#include "hemilight/scene.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hemilight {

/// The kinds of light (values match the C ABI's hemilight_light_type).
enum class light_type : int { directional = 0, point = 1, spot = 2, rect = 3 };

/// One light, as the caller describes it (units and meaning per type: see the top of this header).
struct light {
  light_type type = light_type::point;
  glm::vec3 color{1.0f};                 ///< directional: W/m^2 facing it; point, spot: W/sr; rect: W/m^2/sr (>= 0)
  glm::vec3 position{0.0f};              ///< point, spot: position; rect: centre
  glm::vec3 direction{0.0f, -1.0f, 0.0f};///< directional: travel; spot: axis; rect: normal of the lit side (any length > 0)
  glm::vec3 tangent{1.0f, 0.0f, 0.0f};   ///< rect: direction of its width (any length > 0, not parallel to direction)
  float width = 1.0f, height = 1.0f;     ///< rect: size (m, > 0)
  float radius = 0.0f;                   ///< directional: angular radius (rad, <= pi/2); point, spot: sphere radius (m); 0 = hard
  float spot_inner = 0.0f;               ///< spot: half-angle of full intensity (rad, 0 <= inner <= outer)
  float spot_outer = 0.7853982f;         ///< spot: half-angle past which it is dark (rad, <= pi/2); glTF's default pi/4
  bool casts_shadows = true;             ///< false: no shadow rays, the light reaches every point in front of it
};

/// Checks `count` lights at `lights` and throws error(invalid_argument) for the first bad one, the
/// message naming its index and field ("lights[2].spot_outer = 1.7 is past pi/2"):
///   lights null with count > 0; an unknown type; a NaN or Inf in any float field (all types,
///   used or not: "lights[0].position.y is nan"); a negative color channel; a zero direction
///   (directional, spot, rect); a negative radius (directional, point, spot), or a directional
///   radius past pi/2; spot_inner < 0, spot_inner > spot_outer, spot_outer past pi/2; rect
///   width or height <= 0, a zero tangent, or a tangent within 1e-3 rad of parallel to the
///   normal. Direction lengths are judged after scaling by the largest |component|, so tiny
///   (even subnormal) and huge finite vectors are fine. `array`: the name the message gives the
///   array (a caller's own, e.g. "options->lights"). Cost: O(count).
void validate_lights(const light* lights, std::size_t count, const char* array = "lights");

/// Options of direct_irradiance. The defaults are what bakes use.
struct direct_options {
  /// Interior samples of a soft light traced with the 8 outline probes (>= 0, <= penumbra_samples);
  /// if all agree the light is taken as fully visible or fully blocked (see the top of this
  /// header). Powers of two keep the set a (0, k, 2)-net. So a soft light costs 12 rays where it
  /// is fully visible or fully blocked.
  int probe_samples = 4;
  /// Samples in a penumbra, the interior probes included (<= 65536), so a penumbra point costs
  /// 8 + penumbra_samples rays. Powers of two keep the set a (0, k, 2)-net. The penumbra error
  /// against the count: docs/lights.md.
  int penumbra_samples = 256;
  /// Ray origin offset along the normal: offset_scale x scene.size() + 2^-18 x max |p_i| (the
  /// second term keeps the offset above float rounding far from the origin). 1e-4 is the
  /// rasterizer's near distance (raster.hpp), so shadow rays and hemicubes skip the same
  /// neighbourhood. Must be finite and >= 0.
  float offset_scale = 1e-4f;
};

/// Checks direct_options as direct_light does: throws error(invalid_argument) naming the field
/// ("direct_options: penumbra_samples = 3 must be in [probe_samples = 4, 65536]"). Cost: O(1).
void validate_direct_options(const direct_options& options);

/// The validated lights, prepared for evaluation (unit directions, frames, spot factors). Build it
/// once and share it between threads (immutable).
class light_set {
 public:
  /// No lights.
  light_set() = default;
  /// validate_lights(lights, count) (throws as it does), then copies and prepares the lights.
  /// Cost: O(count); about 200 bytes per light.
  light_set(const light* lights, std::size_t count);

  std::size_t size() const noexcept { return lights_.size(); }
  bool empty() const noexcept { return lights_.empty(); }
  /// Light i as given, except that direction and tangent are unit vectors (rect: tangent made
  /// orthogonal to the normal). Precondition: i < size().
  const light& operator[](std::size_t i) const noexcept { return lights_[i].l; }

  /// Internal: a light with what evaluation derives from it once.
  struct prepared {
    light l;
    glm::vec3 bitangent{0.0f};           ///< rect: n x t; directional and spot: frame of the axis
    float sin2_radius = 0.0f;            ///< directional: sin^2 of the angular radius
    float one_minus_cos_radius = 0.0f;   ///< directional: 1 - cos(radius), computed as 2 sin^2(r/2)
    float spot_scale = 0.0f, spot_offset = 0.0f;
  };
  const prepared& prepared_light(std::size_t i) const noexcept { return lights_[i]; }

 private:
  std::vector<prepared> lights_;
};

/// What one light gives at a point.
struct light_sample {
  glm::vec3 irradiance{0.0f};  ///< E with shadows (RGB, W/m^2) = unoccluded x visibility
  glm::vec3 unoccluded{0.0f};  ///< E without shadows, the closed form (RGB, W/m^2)
  /// Weighted fraction of the light that reaches the point (see the top of this header), in
  /// [0, 1]; 1 for lights that do not cast shadows; 0 where the light is entirely below the
  /// horizon or behind a rect (unoccluded = 0: no ray is traced). Through translucent surfaces
  /// (scene.hpp's surface_opacity): the mean of visibility_rgb's channels.
  float visibility = 0.0f;
  /// The visibility per channel: translucent surfaces on the shadow rays multiply their
  /// transmittance in (rays.hpp's transmittance()); alpha-tested ones block where present. Equal
  /// to visibility in every channel when no translucent surface is in the way. irradiance =
  /// unoccluded x visibility_rgb.
  glm::vec3 visibility_rgb{0.0f};
  /// Unit direction from the point towards the light: the direction of the vector irradiance
  /// (integral of L V w d omega) of its visible part above the horizon, for a directional map's
  /// L1 term. Hard lights: the direction to the light. Soft lights fully visible: the closed
  /// form's (a cone fully above the horizon: its axis; a rect: Lambert's vector on the clipped
  /// polygon); cones across the horizon and penumbrae: the samples' estimate. Zero when the
  /// irradiance is 0.
  glm::vec3 direction{0.0f};
};

/// Unoccluded irradiance of light i at p with unit normal n (the closed forms at the top of this
/// header), RGB W/m^2. Preconditions: i < lights.size(), p finite, |n| = 1 (asserted to 1e-3).
/// Cost: O(1) (rect: clipping and Lambert's formula in double).
glm::vec3 unoccluded_irradiance(const light_set& lights, std::size_t i, const glm::vec3& p, const glm::vec3& n) noexcept;

/// Direct irradiance of light i at p with unit normal n, with shadows against `s`.
/// Throws error(invalid_argument) for bad options (probe_samples < 0, penumbra_samples <
/// probe_samples or > 65536, offset_scale negative or not finite). Deterministic: the result
/// depends only on (s, light, i, p, n, options), bit for bit. Preconditions as
/// unoccluded_irradiance. Cost: hard light one shadow ray; soft light 8 + probe_samples rays,
/// 8 + penumbra_samples in a penumbra (rays.hpp for a ray's cost); none where the closed form
/// is 0 or the light casts no shadows; no allocation.
light_sample direct_light(const scene& s, const light_set& lights, std::size_t i, const glm::vec3& p, const glm::vec3& n,
                          const direct_options& options = {});

/// Sum over all lights of direct_light(...).irradiance (RGB, W/m^2). When `per_light` is not
/// null it receives lights.size() samples, light i's in per_light[i]. Errors, determinism and
/// cost as direct_light, per light.
glm::vec3 direct_irradiance(const scene& s, const light_set& lights, const glm::vec3& p, const glm::vec3& n,
                            const direct_options& options = {}, light_sample* per_light = nullptr);

/// Emissive rectangles as RECT lights, so that their direct light is computed exactly at every
/// point (closed form, shadow rays) instead of seen by hemicubes. Finds pairs of one-sided emissive triangles of `mesh` that share an edge (the same two vertex
/// positions, bit for bit, whatever the indices), have the same emission (bit for bit), face the
/// same way and together form a rectangle: the shared edge is its diagonal, the two other corners
/// see it at right angles and the fourth corner is where a rectangle puts it, each within 1e-4 of
/// the rectangle's diagonal. For each pair it returns a RECT light (centre, normal = the front
/// face, tangent = the side from the first triangle's third corner to the first shared corner,
/// width and height = the side lengths, color = the emission, casts_shadows) and sets both
/// triangles' emission to 0: hemicubes no longer see them as a source, and they stay in the scene
/// (they block and reflect as before). A triangle pairs at most once, greedily in index order.
/// Two-sided emitters, lone triangles and other shapes (parallelograms, triangle fans) are left as
/// they are. Append the result to bake_options::lights. Mesh indices must be < positions.size()
/// (scene::create's checks; here triangles with an index out of range are skipped).
/// Cost: O(emissive triangles) expected (a hash of their edges).
std::vector<light> emissive_rects_to_lights(scene_mesh& mesh);

}  // namespace hemilight
