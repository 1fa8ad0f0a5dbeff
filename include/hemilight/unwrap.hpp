// hemilight/unwrap.hpp — lightmap UVs for any triangle mesh: vertices welded by position, charts
// grown over planar regions by normal deviation, planar charts projected and curved ones flattened
// by least-squares conformal maps, charts turned to their smallest bounding rectangle and packed
// with padding into one or more square pages. How it works, how to call it and its measured
// figures: docs/unwrap.md.
//
// UVs follow bake.hpp's texel convention (texel (x, y) of a page has its centre at
// ((x + 0.5) / size, (y + 0.5) / size)). Every chart keeps the orientation of its triangles (no
// mirrored charts) and one texel density for the whole mesh.
//
// Determinism: the same input and options give the same bytes for any thread count.
#pragma once

#include "hemilight/scene.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hemilight {

/// Largest page size of the unwrapper (texels per side): bake.hpp's max_lightmap_size.
inline constexpr int max_unwrap_page_size = 8192;

/// Options of unwrap_lightmap and generate_lightmap_uvs (checked by validate_unwrap_options).
struct unwrap_options {
  /// Texel density in texels per scene unit, finite and >= 0. 0: the largest density at which
  /// every chart fits one page (a target size); > 0: charts at this density, spilling into as
  /// many pages as they need (at most max_pages).
  float texels_per_unit = 0.0f;
  int page_size = 1024;  ///< width and height of every page in texels, in [16, max_unwrap_page_size]
  /// Empty texels between charts and between a chart and the page border, in [0, 64] and below
  /// page_size / 4. 2 keeps bilinear lookups of one chart off its neighbours.
  int padding = 2;
  /// Largest angle in degrees, in [1, 89], between a triangle's normal and its chart's mean
  /// normal: larger gives fewer charts and more stretch on curved surfaces.
  float max_chart_angle = 60.0f;
  int max_pages = 64;    ///< with texels_per_unit > 0: most pages the charts may need, in [1, 4096]
  int thread_count = 0;  ///< >= 0; 0 = all cores. Results do not depend on it.
};

/// Checks every field's range; throws error(invalid_argument) naming `who` and the field
/// ("unwrap_options: padding 300 is not in [0, 64]"). Cost: O(1).
void validate_unwrap_options(const unwrap_options& options, const std::string& who = "unwrap_options");

/// Figures of one unwrap.
struct unwrap_stats {
  std::size_t charts = 0;                ///< charts packed (planar + curved)
  std::size_t planar_charts = 0;         ///< charts of one planar region, projected onto its plane
  std::size_t degenerate_triangles = 0;  ///< triangles without area (is_degenerate_triangle): in no chart
  int pages = 0;                         ///< pages used (1 with texels_per_unit = 0)
  float texels_per_unit = 0.0f;          ///< the density of every chart (the one found, for a target size)
  /// Sum of the UV areas of the triangles over the pages' area, in [0, 1].
  double uv_area_fraction = 0.0;
  /// Sander et al.'s stretch of the map from UV to surface, after scaling the UVs to the surface's
  /// area (>= 1; 1 for an isometry): L2 the area-weighted root mean square of sqrt((G^2 + g^2) / 2)
  /// over the triangles, L-infinity the largest G (G >= g: the singular values per triangle).
  double stretch_l2 = 1.0, stretch_linf = 1.0;
  /// Seam length in texels: the UV length, on both sides, of every edge whose two triangles lie in
  /// different charts (mesh borders excluded).
  double seam_texels = 0.0;
  double seconds = 0.0;  ///< wall time
};

/// A mesh's new vertices: every input vertex used by a triangle appears once per chart that uses
/// it (and degenerate triangles' corners where they join a chart), at most 3 per triangle.
struct unwrap_result {
  std::vector<std::uint32_t> vertex_source;  ///< per output vertex: the input vertex it copies
  std::vector<glm::vec2> uvs;                ///< per output vertex: its UV in its page, in [0, 1]
  std::vector<std::uint32_t> indices;        ///< 3 per triangle, in input order, into the output vertices
  std::vector<std::uint32_t> triangle_page;  ///< per triangle: its page, < stats.pages
  /// Per triangle: its chart; a degenerate triangle takes the chart of one it touches (its UVs
  /// collapse onto that chart's, without UV area) or, touching none, no_chart (UVs (0, 0), page 0).
  std::vector<std::uint32_t> triangle_chart;
  unwrap_stats stats;

  static constexpr std::uint32_t no_chart = 0xffffffffu;
};

/// Lightmap UVs for the mesh (positions: vertex_count; indices: 3 per triangle, front faces
/// counter-clockwise). Vertices at bit-identical positions (+0 and -0 alike) are one vertex for
/// the charts, however they are indexed. Degenerate triangles (is_degenerate_triangle) join no
/// chart. Only edges shared by two triangles of opposite winding join charts (non-manifold and
/// mirrored neighbours are chart borders).
///
/// Errors (hemilight::error, nothing returned): invalid_argument for bad options
/// (validate_unwrap_options), a null array with a nonzero count, a non-finite or too large
/// position ("unwrap_lightmap: positions[4].y is nan"), an index out of range ("indices[17] = 900
/// is out of range: 12 vertices"), charts that do not fit one page even at one texel each
/// (texels_per_unit = 0) or need more than max_pages pages; out_of_memory for more than
/// max_scene_elements / 3 triangles or vertices over max_scene_elements.
/// Cost: O(V + T log T) for welding and charts, one sparse Cholesky factorisation per curved chart
/// (over the threads), O(C log C + C S) for packing C charts on a skyline of S segments (repeated
/// about 16 times to find the density for a target size). Memory: up to about 350 bytes per
/// triangle at its peak (docs/unwrap.md).
unwrap_result unwrap_lightmap(const glm::vec3* positions, std::size_t vertex_count, const std::uint32_t* indices,
                              std::size_t triangle_count, const unwrap_options& options);

/// Gives `mesh` lightmap UVs by unwrap_lightmap: its positions, lightmap_uvs and indices are
/// replaced by the result's vertices (positions copied from their sources), triangles keep their
/// order and materials. With more than one page (stats.pages), triangle t's UVs lie in page
/// triangle_page[t]: bake such a mesh with bake_scene, one bake_mesh per run of triangles of one
/// page. Errors and cost: as unwrap_lightmap; the mesh is unchanged on error.
unwrap_result generate_lightmap_uvs(scene_mesh& mesh, const unwrap_options& options);

/// The packer of the built-in scenes (boxes, rooms), kept because the reference bakes of the
/// tests, benchmarks and the command-line baker's built-in scenes are made with it: planar groups
/// of edge-connected triangles (same plane, shared edge by position) become charts, each projected
/// onto its plane at one common texel density and packed in shelves into a size x size lightmap
/// with `padding` empty texels between charts (and at the border). Vertices shared by several
/// charts are duplicated; triangles keep their order and materials. Not for meshes with curved
/// surfaces or many charts (use the overload above). Throws error(invalid_argument) for size < 8,
/// padding < 0 or 4 padding >= size. Cost: O(T log T) plus a few packings.
void generate_lightmap_uvs(scene_mesh& mesh, int size, int padding = 2);

}  // namespace hemilight
