// hemilight/probes.hpp — light probes: the radiance arriving at points in free space from all
// directions, projected on real spherical harmonics up to band 2 (SH9, 9 coefficients per colour
// channel), for lighting moving objects; and the irradiance for a normal from them.
//
// The SH basis (real, orthonormal on the sphere, world axes), in coefficient order k:
//   k = 0 (l, m) = (0, 0)   0.282095
//   k = 1        (1, -1)    0.488603 y
//   k = 2        (1, 0)     0.488603 z
//   k = 3        (1, 1)     0.488603 x
//   k = 4        (2, -2)    1.092548 x y
//   k = 5        (2, -1)    1.092548 y z
//   k = 6        (2, 0)     0.315392 (3 z^2 - 1)
//   k = 7        (2, 1)     1.092548 x z
//   k = 8        (2, 2)     0.546274 (x^2 - y^2)
// Coefficient k of a probe = integral over the whole sphere of L(w) Y_k(w) d omega (radiance in
// W m^-2 sr^-1, so a uniform sky of radiance L gives c_0 = 2 sqrt(pi) L and the rest 0).
//
// A probe is two hemicubes of resolution N at the point, up +z (t = +x, b = +y) and down -z
// (t = +x, b = -y), with each basis function integrated exactly over each texel: the only error
// is the texel's constant radiance. Lights (lights.hpp) add their direct part as point sources
// along their visible vector irradiance, shadows included: exact for hard lights, second order
// in the angular size for soft ones and rects. Method and figures: docs/probes.md.
//
// A probe inside closed geometry sees the back faces of one-sided triangles: probe_result's
// backface_fraction (the solid-angle fraction of the sphere that sees back faces) is near 1 for
// it. Its coefficients are then what it sees (mostly black); callers drop such probes (e.g. above
// 0.1, the cache's invalid_backface_fraction) and fill them from neighbours.
#pragma once

#include "hemilight/cubemap.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/scene.hpp"

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

namespace hemilight {

/// Coefficients of one probe: sh9_rgb[k] is coefficient k (order above) of R, G and B.
using sh9_rgb = std::array<glm::vec3, 9>;

/// The 9 basis functions at a unit direction w (world axes), in coefficient order. Precondition:
/// |w| = 1 (not checked; the result scales with |w|^l). Cost: a dozen flops.
std::array<float, 9> sh9_basis(const glm::vec3& w) noexcept;

/// Irradiance E(n) = integral of L(w) max(0, n.w) d omega of the band-limited radiance: the
/// clamped-cosine convolution, E(n) = sum_k A_l c_k Y_k(n) with A_0 = pi, A_1 = 2 pi / 3,
/// A_2 = pi / 4 (Ramamoorthi and Hanrahan 2001). `normal` need not be unit length (it is
/// normalised); a zero or non-finite normal gives 0. Negative results (ringing of a small bright
/// source) are returned as they are (docs/probes.md, "What SH9 can and cannot hold"; a delta
/// source gives 1.0625 x its irradiance facing it). Cost: ~30 flops.
glm::vec3 sh9_irradiance(const sh9_rgb& coefficients, const glm::vec3& normal) noexcept;

/// Options of sample_probes.
struct probe_options {
  int resolution = 64;  ///< hemicube N of each of the two hemicubes: even, in [hemicube_min_resolution, hemicube_max_resolution]
  /// How the hemicubes are drawn: near plane, environment sky (`raster.sky`; null: the scene's
  /// constant sky), exact edge coverage (docs/probes.md).
  raster_options raster;
  int thread_count = 0;                    ///< >= 0; 0 = all cores. Results do not depend on it.
  std::shared_ptr<const light_set> lights; ///< lights (null: none)
  /// Radiance of the surfaces over the scene's lightmap UVs (null: the triangles' emission), e.g.
  /// bake_radiance_texture of a bake (bake.hpp): then the probes see the baked bounce light.
  /// Needs a scene with lightmap UVs; must outlive the call.
  const radiance_texture* texture = nullptr;
  direct_options direct;                  ///< the lights' shadow sampling
};

/// Probes at points.
struct probe_result {
  std::vector<sh9_rgb> probes;            ///< one per point
  std::vector<float> backface_fraction;   ///< per point, in [0, 1]: near 1 inside closed geometry
};

/// Renders two hemicubes at each of `count` points (world) and projects what they see, plus the
/// lights' direct light, on SH9 (the top of this header). Deterministic: each probe depends only
/// on its point, bitwise, whatever the thread count.
/// Errors (error(invalid_argument), naming what): a null scene or positions with count > 0, a
/// non-finite position ("positions[7].y is nan"), an invalid resolution, a negative
/// thread_count, bad direct options, an invalid texture or one on a scene without lightmap UVs.
/// Cost: 2 hemicubes and their projections per point, O(N^2), plus the lights' shadow rays;
/// tables of 36 N^2 floats per N (kept in the table cache of memory.hpp, within its budget).
probe_result sample_probes(std::shared_ptr<const scene> s, const glm::vec3* positions, std::size_t count,
                           const probe_options& options = {});

}  // namespace hemilight
