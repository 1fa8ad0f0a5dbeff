// hemilight/integrate.hpp — from one hemicube buffer to irradiance, gradients and distances.
// Weights are exact and precomputed once per resolution (integration_table): per texel the vector
// solid angle V_i = integral of w dw over the texel, whose z component is the projected solid
// angle; per wall between two neighbouring texels each estimator's coefficient. Derivations and
// measured accuracy: docs/integration.md.
//
// Gradient convention (per colour channel c), world space, both vectors in the tangent plane:
//
//     E_c(x', n') ~= E_c + (n x n') . g_r[c] + (x' - x) . g_t[c]
//
// Rotation gradient: g_r = n x sum_i L_i V_i (exact for the radiance the hemicube sees: the
// irradiance of a fixed radiance field is linear in n while no texel crosses the horizon).
// Translation gradient, three estimators (translation_estimator):
//   simple       sum_i L_i 3 P_i w_t,i / r_i: no parallax, no occlusion (for comparison).
//   classified   Ward & Heckbert's stratified gradient adapted to hemicube walls (for comparison).
//   great_arc    (default) each wall, a great arc with normal m = normalize(d0 x d1), moves at the
//                rate (u.m)/r_min: coefficient m_t * (integral of cos(theta) along the arc) / r_min.
//
// Robustness: misses (distance +inf) contribute to E but a wall uses the finite side's distance
// (a wall between two misses contributes nothing). A wall's distance is clamped from below by
// min_wall_distance (see integrate_options), so geometry at the near plane (distance ~0) gives
// finite gradients bounded by the clamp; nothing here produces Inf or NaN from finite radiance.
#pragma once

#include "hemilight/geometry.hpp"
#include "hemilight/hemicube.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hemilight {

/// Which translation-gradient estimator integrate() uses (see the top of this header).
enum class translation_estimator { none, simple, classified, great_arc };

/// Options of hemicube integration. The defaults are what the irradiance cache uses.
struct integrate_options {
  bool rotation_gradient = true;  ///< compute g_r (cost: ~2 flops per texel and channel)
  translation_estimator translation = translation_estimator::great_arc;  ///< g_t estimator; none skips the wall pass
  /// Lower bound on the distance a wall moves with (scene units, >= 0). 0 = automatic:
  /// 0.1 x the harmonic mean distance of this hemicube (walls nearer than that are treated as
  /// that far, which bounds |g_t| by about 10 x (sum over walls of |dL| x coefficient) / R).
  float min_wall_distance = 0.0f;
  /// Wall distances of the classified and great-arc estimators: false takes the nearer texel's
  /// centre distance (Ward and Heckbert); true extrapolates the nearer texel's inverse distance
  /// half a texel to the wall, from its neighbour on the far side (when that neighbour's depth is
  /// closer to it than the other texel's, i.e. the wall is the discontinuity), clamped to [1/2, 2]
  /// x the centre's: for planes seen at a grazing angle (docs/integration.md, section 6). Cost:
  /// one more pass over the walls without the AVX2 kernels.
  bool extrapolate_wall_depth = false;
  bool directional = false;  ///< also compute L1 spherical harmonics and the Half-Life 2 basis irradiance
  bool double_precision = false;  ///< accumulate in double instead of float (slower; for checks)
  /// Float path: use the hand-written AVX2 + FMA kernels where the CPU has both (checked at run
  /// time). false selects the portable loops the compiler vectorises (for tests and comparisons);
  /// both give the same sums up to float rounding order.
  bool simd_kernels = true;
};

/// Throws error(invalid_argument) naming the field, the message starting with `who`, when
/// min_wall_distance is negative or not finite. Cost: O(1).
void validate_integrate_options(const integrate_options& options, const std::string& who);

/// Everything integrate() computes from one hemicube. Vectors are world space.
struct irradiance_sample {
  glm::vec3 irradiance{0.0f};  ///< E per channel (RGB), integral of L cos(theta) d omega
  std::array<glm::vec3, 3> rotation_gradient{};     ///< g_r per channel [R, G, B]; zero if not computed
  std::array<glm::vec3, 3> translation_gradient{};  ///< g_t per channel [R, G, B]; zero if not computed
  /// Split-sphere distance: 1 / (sum_i P_i / r_i / sum_i P_i) over all texels with misses as
  /// infinitely far; +inf if nothing was hit.
  float harmonic_mean_distance = 0.0f;
  float min_distance = 0.0f;       ///< smallest hit distance (front or back face); +inf if nothing was hit
  float backface_fraction = 0.0f;  ///< projected-solid-angle fraction of texels that see back faces, [0, 1]
  /// L1 spherical harmonics of the incoming radiance (zero below the horizon), world-space
  /// directions, real SH order Y00, Y1-1 (y), Y10 (z), Y11 (x) with Y00 = 0.282095,
  /// Y1m = 0.488603 * (y, z, x). Coefficient k, channel c: sh_l1[k][c]. Only if directional.
  std::array<glm::vec3, 4> sh_l1{};
  /// Irradiance through the three Half-Life 2 basis vectors of the hemicube's own frame
  /// (t, b, n): (-1/sqrt6, 1/sqrt2, 1/sqrt3), (-1/sqrt6, -1/sqrt2, 1/sqrt3), (sqrt(2/3), 0, 1/sqrt3).
  /// Per texel the clamped max(0, V_i . b_k), exact for texels wholly above b_k's horizon.
  /// Only if directional. Render with the lightmap's tangent frame to get engine-ready values.
  std::array<glm::vec3, 3> hl2{};
};

/// Per-resolution weights of the integrator, computed once in double and stored as float.
/// Memory: 69 bytes per texel plus 6 N walls (N = 64: 0.8 MiB, N = 256: 13 MiB, N = 1024: 204 MiB).
class integration_table {
 public:
  /// The shared table of resolution N (cached like hemicube_table: in the table cache of
  /// memory.hpp, within its budget; a table in use lives while held). Cost of a build: O(N^2).
  /// Throws error(invalid_argument) for an invalid N.
  static std::shared_ptr<const integration_table> get(int n);
  explicit integration_table(int n);  ///< builds a private table; prefer get()

  int resolution() const noexcept { return n_; }

  /// A wall between texels a and b with a 2D coefficient (local x, y) per estimator;
  /// contribution to g_t (local) = (L_b - L_a) * coefficient / max(min(r_a, r_b), floor).
  struct wall {
    std::uint32_t a, b;
    float great_arc[2];
    float classified[2];
  };

  // Per texel (3 N^2 entries each).
  std::vector<float> vx, vy, vz;  ///< vector solid angle (local); vz = projected solid angle
  std::vector<float> simple_x, simple_y;  ///< 3 P_i w_i,xy: the simple estimator's weights
  std::vector<float> hl2[3];              ///< max(0, V_i . b_k) for the three HL2 basis vectors
  std::vector<float> solid_angle;         ///< for band 0 of the SH
  /// Walls inside faces between texel i and i+1 (same row) and i and i+N (next row), indexed by
  /// the lower texel i; entries of the last column / row are zero (no wall).
  std::vector<float> right_great_arc_x, right_great_arc_y, up_great_arc_x, up_great_arc_y;
  std::vector<float> right_classified_x, right_classified_y, up_classified_x, up_classified_y;
  std::vector<wall> border_walls;  ///< walls across face borders (6 N of them)
  /// Per texel, which neighbours the wall-depth extrapolation may use (in the same face):
  /// bit 0 x - 1, bit 1 x + 2, bit 2 y - 1, bit 3 y + 2.
  std::vector<std::uint8_t> extrapolation_neighbours;

 private:
  int n_;
};

/// Reduces hemicube buffers of one resolution; holds its table and scratch memory. Use one per
/// thread (not thread-safe; the table it points to is shared and immutable).
class hemicube_integrator {
 public:
  /// Throws error(invalid_argument) for an invalid resolution or a negative/NaN
  /// min_wall_distance in options.
  explicit hemicube_integrator(int resolution, const integrate_options& options = {});

  /// Integrates one buffer. Precondition: buffer.resolution == resolution() and the buffer's
  /// arrays have 3 N^2 entries (throws error(invalid_argument) otherwise); radiance finite and
  /// >= 0, distances > 0 or +inf (asserted in debug builds). Cost: O(N^2) (3 N^2 texels, about
  /// 6 N^2 walls); less for mostly black hemicubes, whose black texel groups the AVX2 kernels
  /// skip. The result does not depend on the hemicubes this integrator saw before.
  irradiance_sample integrate(const hemicube_buffer& buffer);

  int resolution() const noexcept { return n_; }
  const integrate_options& options() const noexcept { return options_; }

 private:
  template <class Acc>
  irradiance_sample run(const hemicube_buffer& buffer);

  int n_;
  integrate_options options_;
  std::shared_ptr<const integration_table> table_;
  std::vector<float> inv_r_;  // scratch: 1/distance per texel
  std::vector<float> wall_inv_;  // scratch (extrapolate_wall_depth): 1/distance of each right wall, then each upper wall
  std::vector<std::uint8_t> lit_;  // scratch (AVX2 kernels): per group of 8 texels, any radiance non-zero
  bool map_black_ = true;  // map black groups in the next hemicube (the last mapped one had many)
  int unmapped_ = 0;       // hemicubes since the last mapped one
};

/// Convenience: integrate one buffer with a temporary integrator (fetches the cached table;
/// allocates scratch each call). Prefer a hemicube_integrator per thread in loops.
irradiance_sample integrate(const hemicube_buffer& buffer, const integrate_options& options = {});

}  // namespace hemilight
