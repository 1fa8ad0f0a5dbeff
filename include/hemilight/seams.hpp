// hemilight/seams.hpp — lightmap seams: where a surface is cut into two charts (or two meshes, or
// two pages), the texels on each side of the cut are separate and bilinear filtering shows a step
// along the 3D edge. measure_seams finds the seams of a baked scene and measures the step the way
// an engine shows it; the baker removes it (bake_options::stitch_seams). docs/bake.md, "Seams".
//
// What a seam is: a 3D segment shared, by position, by two triangles with texels whose lightmap
// UVs differ across it (another chart, another page, or the same chart at another place). Shared
// by position means: the two triangle edges have bit-identical endpoints (+0 and -0 alike), or
// they lie on one line and overlap (T-junctions: an endpoint of one edge lies on the other, within
// seam_position_tolerance x the edge's length). Degenerate triangles (no 3D area, or no UV area)
// and triangles without texels (bake_scene's occluders) have no seams. Pieces whose two sides'
// UVs agree within seam_uv_tolerance texels at both ends are one chart, not a seam.
//
// A seam between near-coplanar faces with a surface standing on it (a wall on a floor whose two
// rooms' floors are separate charts) is walled: there the lighting legitimately differs, so it is
// measured apart (seam_report::walled) and never stitched. Walled means: of seam_wall_points
// segments across the piece, from half a texel into one side to half a texel into the other
// (perpendicular to the edge in each triangle's plane, also where the triangle is thinner, lifted
// off its face by 0.01 + tan(theta / 2) times that distance, theta the angle between the two
// faces), some segment hits a triangle of the scene.
//
// Sampling (the texel convention of bake.hpp): a side is read bilinearly at its UV along the
// piece, texel (x, y) centred at ((x + 0.5) / W, (y + 0.5) / H), clamp-to-edge in its page.
#pragma once

#include "hemilight/bake.hpp"

#include <cstddef>

namespace hemilight {

/// Largest distance of a T-junction's vertex from the other edge, relative to that edge's length,
/// for the two edges to count as one seam (1e-5: far above float rounding of coordinates computed
/// by interpolation along the edge, far below any modelled gap).
inline constexpr float seam_position_tolerance = 1e-5f;

/// Largest UV difference, in texels of the page, between the two sides of a shared edge at both of
/// its ends for the edge to count as the inside of one chart rather than a seam (1e-3 texel:
/// rounding of UVs interpolated at a T-junction).
inline constexpr float seam_uv_tolerance = 1e-3f;

/// The seams the baker stitches (bake_options::stitch_seams): shading normals within this angle
/// (degrees) of each other at both ends of the piece. Tighter than seam_options::coplanar_degrees:
/// where flat-shaded faces meet at an angle the lighting legitimately differs across the edge (by
/// about tan(angle) of a light at grazing incidence), and a converged bake shows that step too.
inline constexpr float seam_stitch_degrees = 1.0f;

/// Segments across each near-coplanar piece (at 0.1, 0.3, ..., 0.9 of its length) that decide
/// whether a surface stands on it (walled).
inline constexpr int seam_wall_points = 5;

/// How measure_seams samples and classifies the seams.
struct seam_options {
  /// Near-coplanar seams: the shading normals of the two sides (interpolated vertex normals, or
  /// face normals) within this angle (degrees, in (0, 90]) of each other at both ends of the
  /// piece. Only these make the headline figure; across a crease the lighting legitimately
  /// differs (seam_report::crease).
  float coplanar_degrees = 5.0f;
  /// Sample points per texel of seam length, finite, in [0.25, 64]: each piece gets
  /// max(1, ceil(samples_per_texel x its length in texels)) points at the centres of equal parts.
  float samples_per_texel = 4.0f;
  /// The step counted in seam_figures::step_fraction (relative, finite, >= 0).
  float step_threshold = 0.02f;
};

/// The step along one class of seams. The relative step at a sample point is
///   |Y_a - Y_b| / max((Y_a + Y_b) / 2, seam_report::floor)
/// with Y the luminance (0.2126 R + 0.7152 G + 0.0722 B) of each side's bilinear lookup; each
/// point stands for its share of the piece's length, and the figures are length-weighted.
struct seam_figures {
  std::size_t pieces = 0;      ///< seam pieces (two triangle edges overlapping along a 3D segment)
  std::size_t samples = 0;     ///< sample points
  double length_texels = 0.0;  ///< summed length, each piece's the mean of its two sides' UV lengths in texels
  double rms = 0.0;            ///< RMS of the relative step (length-weighted)
  double p95 = 0.0;            ///< 95th percentile of the relative step (by length)
  double max = 0.0;            ///< largest relative step
  double step_fraction = 0.0;  ///< share of the length whose relative step exceeds step_threshold
};

/// What measure_seams returns.
struct seam_report {
  seam_figures coplanar;  ///< seams between near-coplanar faces (seam_options::coplanar_degrees): the headline
  seam_figures crease;    ///< seams across a crease (normals further apart)
  seam_figures walled;    ///< near-coplanar seams with a surface standing on them (never stitched)
  /// Seam length (texels, all classes) not counted above: points where a side's bilinear
  /// footprint holds no valid texel (bake_result::valid; sampled where valid is empty), so that
  /// side is inside geometry there and nobody sees the step.
  double hidden_length_texels = 0.0;
  /// The relative step's floor: 5% of the mean luminance of the sampled texels (all pages), so
  /// that steps in nearly black regions do not count as large.
  double floor = 0.0;
};

/// Finds the seams of a bake_lightmap input (one page: the whole lightmap) and measures the step
/// of result.irradiance along them. Reads input.scene's positions, indices and lightmap UVs
/// (input.normals for the coplanar test), result.irradiance, result.sampled and result.valid
/// (may be empty). Builds the scene's rays for the walled test.
/// Errors (error(invalid_argument), naming the argument): options out of range; no lightmap UVs,
/// an index out of range, a UV more than lightmap_uv_tolerance outside [0, 1]; a result whose irradiance is not an RGB image or whose sampled array
/// does not match it, a valid array neither empty nor of that size. Non-finite texels are read as
/// they are (the bake writes none).
/// Cost: O(E log E) for E triangle edges (sorting, a grid of the vertices for T-junctions), the
/// scene's Embree build and 5 rays per near-coplanar piece, plus O(sample points).
seam_report measure_seams(const bake_input& input, const bake_result& result, const seam_options& options = {});

/// The same for a bake_scene input and result: seams within a mesh, between meshes and between
/// pages, each side read in its own page (page UVs: the mesh's uv_scale and uv_offset applied).
/// Occluder-only meshes have no seams. Errors: as above, and a result with another page count or
/// page sizes than the input, or meshes not covering the triangles ("meshes[2] ...").
seam_report measure_seams(const scene_bake_input& input, const scene_bake_result& result, const seam_options& options = {});

}  // namespace hemilight
