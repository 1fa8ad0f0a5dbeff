// hemilight/sampler.hpp — irradiance at a point from one hemicube: the sampler stage between the
// integrator and its consumers (the cache, the baker).
//
// A sampler renders a hemicube at (position, normal) (raster.hpp), reduces it (integrate.hpp) and,
// on request, projects it onto the directional bases the baker writes: world-space L1 SH and the
// irradiance on the cone of Half-Life 2 directions (hl2_cone); and, on request, the ambient
// occlusion within a distance from the same buffer's distances. The cache calls it through
// `irradiance_sampler`, a plain function, and knows nothing else of this stage.
// Directional conventions and measured accuracy: docs/bake.md ("Directional lightmaps").
#pragma once

#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"

#include <array>
#include <functional>
#include <memory>
#include <string>

namespace hemilight {

// ---- the HL2 cone -------------------------------------------------------------------------------

/// Order of the azimuthal Fourier series of hl2_cone.
inline constexpr int hl2_cone_order = 3;
/// Number of its coefficients: a_0, then a_m, b_m for m = 1..hl2_cone_order.
inline constexpr int hl2_cone_terms = 2 * hl2_cone_order + 1;

/// The Half-Life 2 basis in a tangent frame (t, b, n): local coordinates of its three unit
/// vectors, mutually orthogonal, each 54.74 degrees from n.
inline constexpr float hl2_basis[3][3] = {
    {-0.408248290f, 0.707106781f, 0.577350269f},
    {-0.408248290f, -0.707106781f, 0.577350269f},
    {0.816496581f, 0.0f, 0.577350269f},
};

/// Irradiance through every direction b(phi) = n / sqrt3 + sqrt(2/3) (cos phi r + sin phi (n x r))
/// of the HL2 cone at a point of normal n, as a Fourier series in the azimuth phi (from the unit
/// tangent r = `reference` towards n x r), per channel:
///     E(b(phi)) ~= a_0 + sum_{m=1..3} (a_m cos(m phi) + b_m sin(m phi)),
/// coefficients = {a_0, a_1, b_1, a_2, b_2, a_3, b_3}. Exact (to quadrature) for radiance within
/// 35.26 degrees of n; otherwise the harmonics above 3 of the clamped cosine are cut.
struct hl2_cone {
  glm::vec3 reference{1.0f, 0.0f, 0.0f};  ///< unit tangent (world space) at phi = 0
  std::array<glm::vec3, hl2_cone_terms> coefficients{};  ///< [term][channel]
};

/// The same cone with its azimuth measured from `reference` (a unit tangent of `normal`, the
/// cone's normal; projected onto the tangent plane when it is not in it): an exact rotation of
/// the series. Cost: one atan2 and 3 sincos.
hl2_cone rotate_hl2_cone(const hl2_cone& cone, const glm::vec3& normal, const glm::vec3& reference) noexcept;

/// E(b(phi)) of the series at azimuth phi (radians), per channel, not clamped. Cost: O(hl2_cone_order).
glm::vec3 evaluate_hl2_cone(const hl2_cone& cone, float phi) noexcept;

/// The three HL2 values (hl2_basis) of the tangent frame f (f.n = the cone's normal; left-handed
/// frames are fine: the basis follows the frame), clamped at 0. Cost: 3 evaluations.
std::array<glm::vec3, 3> hl2_from_cone(const hl2_cone& cone, const frame& f) noexcept;

// ---- L1 SH ----------------------------------------------------------------------------------------

/// Irradiance of a plane of unit normal d from world-space L1 SH coefficients of incoming radiance
/// (integrate.hpp's order and normalisation): (sqrt(pi)/2) c_00 + sqrt(pi/3) (c_11 d.x + c_1-1 d.y
/// + c_10 d.z), per channel, clamped at 0. Exact for radiance in SH bands 0 and 1 and for a
/// uniform sky over any hemisphere. Cost: O(1).
glm::vec3 sh_l1_irradiance(const std::array<glm::vec3, 4>& sh, const glm::vec3& d) noexcept;

/// The three HL2 values of frame f (unit, orthogonal; left-handed allowed) from L1 SH alone:
/// sh_l1_irradiance along the world directions of hl2_basis in f. Loses the band >= 2 part of the
/// clamped cosine (docs/bake.md measures it); the baker's own HL2 maps use the cone. Cost: O(1).
std::array<glm::vec3, 3> hl2_from_sh_l1(const std::array<glm::vec3, 4>& sh, const frame& f) noexcept;

// ---- samplers -------------------------------------------------------------------------------------

/// What a sampler returns: the integrator's sample plus, when requested, the HL2 cone and the
/// ambient occlusion (zero otherwise). Converts implicitly from an irradiance_sample.
struct sampler_result : irradiance_sample {
  hl2_cone cone;
  /// With sampler_pass::ao_distance > 0 (else 0): the cosine-weighted fraction of the hemisphere
  /// that sees nothing within that distance, sum_i w_i [distance_i > D] / sum_i w_i over the
  /// hemicube's texels (w_i: the integrator's projected solid angles, integration_table::vz;
  /// distance_i: hemicube_buffer::distance, Euclidean, +inf for misses; back faces occlude like
  /// front faces). In [0, 1]: exactly 1 when nothing lies within D, exactly 0 when every texel
  /// sees geometry within D. docs/bake.md, "Ambient occlusion".
  float ao = 0.0f;
  sampler_result() = default;
  sampler_result(const irradiance_sample& s) : irradiance_sample(s) {}  // NOLINT: implicit on purpose
};

/// Irradiance at (position, unit normal), world space. `worker` in [0, workers) picks a
/// per-thread context. Must be deterministic in its arguments (apart from worker) and thread-safe
/// across different workers.
using irradiance_sampler = std::function<sampler_result(int worker, const glm::vec3& position, const glm::vec3& normal)>;

/// How a hemicube sampler renders and integrates.
struct sampler_options {
  int resolution = 64;          ///< hemicube N: even, in [hemicube_min_resolution, hemicube_max_resolution]
  raster_options raster;        ///< near plane, environment sky, exact edge coverage
  integrate_options integrate;  ///< estimators (the defaults are the cache's)
  /// Turn each hemicube about its normal by an angle hashed from the position's bits: deterministic,
  /// and the texel grid's aliasing becomes fine noise instead of bands.
  bool roll = true;
};

/// What one use of a sampler sees and computes besides irradiance (a bake decides it per pass).
struct sampler_pass {
  /// Radiance texture sampled at the lightmap UV of what each texel sees (bounce passes); null:
  /// the triangles' emission. Must outlive the sampler.
  const radiance_texture* texture = nullptr;
  /// Fill irradiance_sample::sh_l1 (world-space L1 SH) cheaply: band 1 from the vector irradiance
  /// the rotation gradient holds, band 0 from exact texel solid angles. Needs
  /// integrate.rotation_gradient. Cost: 3 multiply-adds per texel.
  bool sh_l1 = false;
  /// Fill sampler_result::cone (reference = the hemicube's rolled tangent). Cost: 21 multiply-adds
  /// per texel and a table of 28 bytes per texel per resolution (table cache, memory.hpp).
  bool hl2_cone = false;
  /// Fill sampler_result::ao: the ambient occlusion within this distance (scene units, finite,
  /// >= 0; 0 = not computed, the default). Cost: one compare and add per texel, from the buffer
  /// the irradiance comes from (no second render).
  float ao_distance = 0.0f;
};

/// Checks the options and throws error(invalid_argument) naming the field, the message starting
/// with `who`: resolution, raster (validate_raster_options), integrate (validate_integrate_options).
/// Cost: O(1).
void validate_sampler_options(const sampler_options& options, const std::string& who);

/// A sampler that renders `scene` with one rasterizer, integrator and buffer per worker (`workers`
/// of them; each worker makes its context on its first call). Throws error(invalid_argument) for a
/// null scene, workers < 1, invalid options, an invalid texture, pass.sh_l1 without
/// integrate.rotation_gradient, or pass.ao_distance negative or not finite (the message names
/// "ao_distance"). The sampler throws error(invalid_argument) for a worker out of range. Cost per
/// call: one render and one integration (raster.hpp, integrate.hpp), plus what the pass asks for.
irradiance_sampler make_hemicube_sampler(std::shared_ptr<const scene> scene, const sampler_options& options, int workers,
                                         const sampler_pass& pass = {});

}  // namespace hemilight
