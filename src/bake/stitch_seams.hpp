// Seam stitching (internal, not installed): the baker's step that makes both sides of every
// near-coplanar seam agree under bilinear filtering (bake_options::stitch_seams; docs/bake.md,
// "Seams"). Least squares over the texels the sides' bilinear footprints touch:
//   minimise  sum over seam points s of w_s (f_a(s) - f_b(s))^2  +  lambda sum over texels (x - x_baked)^2
// f_a, f_b: the two sides' bilinear lookups (clamp-to-edge per page); the points are 3 Gauss-Legendre
// nodes on every part of a piece between two texel-centre lines of either side, so that the first
// sum is the exact integral of the squared step along the seam (w_s: the node's share of the
// piece's length in texels). Solved through the normal equations (A^T W A + lambda I) x = lambda x_baked
// with Eigen's SimplicialLDLT, once per system, for every channel.
// Discontinuities on a seam (a hard shadow edge along it) are kept: a point whose step in the
// irradiance is larger than 3 x the two sides' gradients (the change of each side's lookup between
// 1 and 2 texels inside it) plus 10% of the two sides' mean is dropped from every system, since
// sampling at other distances from the seam explains a step of about a texel's change at most.
#pragma once

#include "seam_search.hpp"

#include "hemilight/image_io.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace hemilight::bake_detail {

// The weight of the texels' own values against the step, per texel, in units of seam length in
// texels: small enough that the step decides wherever the texels can remove it, large enough that
// the system stays well conditioned (its smallest eigenvalue). docs/bake.md, "Seams", measures it.
inline constexpr double stitch_regularization = 0.01;

// A seam point: both sides' bilinear footprints in the grid, its weight (length in texels), and
// each side's lightmap tangent frame (for the HL2 maps).
struct stitch_point {
  footprint a, b;
  std::array<footprint, 2> a_in, b_in;  // each side's lookups 1 and 2 texels inside it
  double weight = 0.0;
  glm::vec3 ta{0.0f}, ba{0.0f}, tb{0.0f}, bb{0.0f};
};

// The stitching systems of the near-coplanar pieces in a grid `grid_width` texels wide holding
// the pages at `pages` (built once per bake; solved once per image).
class seam_stitcher {
 public:
  // Builds the seam points, drops those where the irradiance (grid-sized RGB as baked, the sampled
  // texels in `filled`) jumps across the seam (see the top), and factorises the scalar system (and
  // the HL2 system when `hl2`). Cost: O(points) to assemble; the factorisation of a matrix whose
  // graph is the seams' footprints (chains along each seam: about linear in the unknowns).
  seam_stitcher(const std::vector<seam_piece>& pieces, const std::vector<page_rect>& pages, int grid_width, bool hl2,
                const image& irradiance, const std::vector<std::uint8_t>& filled, const std::uint8_t* blocked);
  ~seam_stitcher();
  seam_stitcher(const seam_stitcher&) = delete;
  seam_stitcher& operator=(const seam_stitcher&) = delete;

  bool empty() const { return texels_.empty(); }
  // The points dropped as discontinuities.
  std::size_t discontinuities() const { return discontinuities_; }
  // The unknown texels (grid indices, increasing).
  const std::vector<std::size_t>& texels() const { return texels_; }
  const std::vector<stitch_point>& points() const { return points_; }

  // Stitches every channel of img (grid-sized): the unknown texels get the least-squares values,
  // clamped to [lo, hi], pulled towards their current values (texels not yet filled: the mean of
  // the filled, unblocked texels in the nearest of 4 rings around them). Marks them in `filled`.
  // Cost: O(unknowns) plus one solve per channel.
  void stitch(image& img, std::vector<std::uint8_t>& filled, const std::uint8_t* blocked, float lo, float hi) const;

  // The three HL2 images together (each texel's triple in its own tangent frame): per seam point
  // the two sides' mean and world-space first harmonic over the HL2 cone agree. Values clamped at
  // 0. Precondition: built with hl2.
  void stitch_hl2(std::array<image, 3>& hl2, std::vector<std::uint8_t>& filled, const std::uint8_t* blocked) const;

 private:
  struct system;
  std::vector<std::size_t> texels_;
  std::vector<stitch_point> points_;
  std::size_t discontinuities_ = 0;
  std::unique_ptr<system> scalar_, hl2_;
};

// The Gauss-Legendre points of the near-coplanar pieces (see the top), in the grid.
std::vector<stitch_point> stitch_points(const std::vector<seam_piece>& pieces, const std::vector<page_rect>& pages,
                                        std::size_t grid_width);

}  // namespace hemilight::bake_detail
