// The unwrapper's steps (internal, not installed): unwrap_lightmap (unwrap.hpp) runs
//   weld_and_link -> grow_charts -> parameterize_charts -> orient_charts -> split_sparse_charts
//   [-> split_large_charts] -> pack_charts -> emit_vertices -> measure_unwrap
// Each step reads what the ones before it made and adds its own arrays.
#pragma once

#include "hemilight/unwrap.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hemilight::unwrap_detail {

constexpr std::uint32_t none = 0xffffffffu;

// The caller's mesh (checked by unwrap_lightmap).
struct mesh_view {
  const glm::vec3* positions = nullptr;
  std::size_t vertex_count = 0;
  const std::uint32_t* indices = nullptr;
  std::size_t triangle_count = 0;

  glm::dvec3 corner(std::size_t t, int k) const { return glm::dvec3(positions[indices[3 * t + std::size_t(k)]]); }
};

// Step 1: vertices welded by position, per-triangle normals and areas, and the edges that link
// two triangles (shared by exactly two non-degenerate triangles with opposite winding).
struct welded_mesh {
  std::vector<std::uint32_t> weld;       // per input vertex: its welded vertex in [0, welded_count)
  std::size_t welded_count = 0;
  std::vector<glm::dvec3> normal;        // per triangle: unit normal ((0, 0, 0) if degenerate)
  std::vector<double> area;              // per triangle: 3D area (0 if degenerate)
  std::vector<std::uint8_t> degenerate;  // per triangle: is_degenerate_triangle
  std::size_t degenerate_count = 0;
  // Per triangle edge 3 t + e (from corner e to corner e + 1): the linked edge 3 t' + e', or none.
  std::vector<std::uint32_t> neighbour;
  // Per triangle edge: the next edge in a ring of all the edges at the same welded vertex pair,
  // linked or not (a single edge points to itself; degenerate triangles' edges: none). For seams.
  std::vector<std::uint32_t> same_edge;

  std::uint32_t welded(const mesh_view& m, std::size_t t, int k) const { return weld[m.indices[3 * t + std::size_t(k)]]; }
};
// Cost: O(V) expected for the weld (hashing), O(T log T) for the edges.
welded_mesh weld_and_link(const mesh_view& m);

// Step 2: planar regions (edge-linked triangles whose normals lie within a hair of the region
// seed's), grown into charts: a chart takes neighbouring regions while each stays within the
// chart angle of the chart's area-weighted mean normal, nearest normal first.
struct chart_set {
  std::vector<std::uint32_t> triangle_region;  // per triangle: its planar region, or none (degenerate)
  std::vector<std::uint32_t> triangle_chart;   // per triangle: its chart, or none (degenerate)
  std::vector<std::uint32_t> first;            // C + 1 offsets into `triangles`
  std::vector<std::uint32_t> triangles;        // each chart's triangles, increasing
  std::vector<std::uint8_t> planar;            // per chart: one planar region (projected)
  std::vector<glm::dvec3> normal;              // per chart: area-weighted mean normal (unit)

  std::size_t size() const { return first.empty() ? 0 : first.size() - 1; }
  // Appends a chart of `tris` (increasing) and sets their triangle_chart.
  void add(const std::vector<std::uint32_t>& tris, bool is_planar, const glm::dvec3& n);
};
// Cost: O(T log T).
chart_set grow_charts(const mesh_view& m, const welded_mesh& w, double max_chart_angle_degrees);

// Steps 3 and 4: every chart's vertices (welded vertices, increasing) and their UVs, in scene
// units: made by parameterize_charts, then turned and moved by orient_charts so that the chart's
// smallest bounding rectangle is [0, extent.x] x [0, extent.y].
struct chart_uvs {
  std::vector<std::uint32_t> first;   // C + 1 offsets into vertex and uv
  std::vector<std::uint32_t> vertex;  // welded vertices of each chart, increasing
  std::vector<glm::dvec2> uv;
  std::vector<glm::dvec2> extent;     // per chart (orient_charts)

  // The index of welded vertex v in chart c's arrays, or none.
  std::uint32_t find(std::size_t c, std::uint32_t v) const;
};
// Planar charts are projected onto their plane; curved ones are solved by least-squares
// conformal maps (Eigen's sparse LDLT on the normal equations, two vertices pinned) and scaled to
// their 3D area; a curved chart whose map flips a triangle is split into its planar regions,
// each projected. Charts may be renumbered by such splits (`charts` is updated). Cost: one sparse
// factorisation per curved chart, charts spread over `thread_count` threads.
chart_uvs parameterize_charts(const mesh_view& m, const welded_mesh& w, chart_set& charts, int thread_count);

// Turns a chart's UVs so that its smallest-area bounding rectangle (over its convex hull's edges,
// by rotating calipers) is axis-aligned with its corner at the origin, wider than tall (a quarter
// turn keeps the orientation); returns the extent. Cost: O(n log n) for n vertices.
glm::dvec2 orient_chart(glm::dvec2* uv, std::size_t count);
// orient_chart for every chart; sets extent.
void orient_charts(chart_uvs& uvs);

// Step 5: charts cut across their longer side (the pieces keep their UVs and are re-oriented).
// split_sparse_charts cuts charts that fill little of their rectangle when the halves' rectangles
// at `density` (texels per scene unit), grown by `padding`, take less room (split_charts.cpp's
// constants); split_large_charts cuts charts longer than `limit` (scene units) until all fit, and
// throws error(invalid_argument) for a single triangle longer than that, naming it and its size at
// `density`. Cost: O(n log n) per cut of a chart of n triangles.
void split_sparse_charts(const mesh_view& m, const welded_mesh& w, chart_set& charts, chart_uvs& uvs, double density, int padding);
// The density at which the charts' rectangles would fill `fill` of one page (an estimate of the
// density a target size ends at). Cost: O(C).
double estimate_density(const chart_uvs& uvs, const unwrap_options& o, double fill);
void split_large_charts(const mesh_view& m, const welded_mesh& w, chart_set& charts, chart_uvs& uvs, double limit, double density);

// Step 6: where every chart goes: its page and the texel offset of its rectangle's corner, turned
// by 90 degrees or not. Density: options.texels_per_unit, or the largest that fits one page.
struct placement {
  std::vector<std::uint32_t> page;  // per chart
  std::vector<glm::dvec2> origin;   // per chart: texel position of UV (0, 0) of the oriented chart
  std::vector<std::uint8_t> turned; // per chart: u and v swapped (a quarter turn, orientation kept)
  int pages = 0;
  double density = 0.0;             // texels per scene unit
};
// Throws error(invalid_argument) when the charts do not fit (see unwrap_lightmap).
placement pack_charts(const chart_uvs& uvs, const unwrap_options& o);

// The UV in [0, 1] of chart c's vertex i (an index into uvs' arrays) after packing.
glm::vec2 page_uv(const chart_uvs& uvs, const placement& p, std::size_t c, std::size_t i, int page_size);

// Step 7: the output vertices (unwrap_result's vertex_source, uvs, indices, triangle_page,
// triangle_chart). Cost: O(T).
void emit_vertices(const mesh_view& m, const welded_mesh& w, const chart_set& charts, const chart_uvs& uvs,
                   const placement& p, int page_size, unwrap_result& out);

// Step 8: stretch, seams and UV area of the result (unwrap_stats). Cost: O(T).
void measure_unwrap(const mesh_view& m, const welded_mesh& w, const placement& p, int page_size, unwrap_result& out);

}  // namespace hemilight::unwrap_detail
