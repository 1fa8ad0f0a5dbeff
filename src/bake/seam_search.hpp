// The seams of a lightmap (internal, not installed): which 3D segments two triangles with texels
// share while their lightmap UVs differ across them (seams.hpp defines a seam), and how a side is
// read bilinearly in its page. Used by measure_seams (the metric) and the baker's stitching step.
#pragma once

#include "hemilight/seams.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace hemilight::bake_detail {

// A lightmap page's rectangle in the texel grid the values live in (bake_scene's atlas; the whole
// lightmap for bake_lightmap; a page's own image for the metric).
struct page_rect {
  int x = 0, y = 0, width = 0, height = 0;
};

// The triangles as the seam search reads them. UVs per triangle corner (3 per triangle), in page
// UV units ([0, 1]); `triangle_page` per triangle (-1: no texels), or null: all in page 0.
struct seam_mesh {
  const glm::vec3* positions = nullptr;
  std::size_t vertex_count = 0;
  const std::uint32_t* indices = nullptr;
  std::size_t triangle_count = 0;
  const glm::vec3* normals = nullptr;  // per vertex, any length, or null: face normals
  const glm::vec2* corner_uvs = nullptr;
  const int* triangle_page = nullptr;
  std::vector<page_rect> pages;
};

// One side of a seam piece: its triangle and page, its texel coordinates in the page (UV x page
// size) at the piece's two ends, its unit shading normals there, and its lightmap tangent frame
// (lightmap_tangent_frame) at the piece's middle.
struct seam_side {
  std::uint32_t triangle = 0;
  int page = 0;
  glm::vec2 t0{0.0f}, t1{0.0f};
  glm::vec2 inward{0.0f};  // unit, in texel units: perpendicular to t1 - t0, towards the triangle
  glm::vec3 n0{0.0f}, n1{0.0f};
  glm::vec3 tangent{0.0f}, bitangent{0.0f};
};

// A seam piece: a 3D segment from p0 to p1 that sides a and b share.
struct seam_piece {
  seam_side a, b;
  glm::vec3 p0{0.0f}, p1{0.0f};
  float length_texels = 0.0f;  // the mean of the two sides' UV lengths, in texels
  bool coplanar = false;       // shading normals within the angle at both ends
  bool walled = false;         // a surface stands on the seam: the sides cannot see each other (seams.hpp)
};

// The seam pieces of m (seams.hpp), in a fixed order (by the pair of triangle edges). coplanar
// marks pieces whose sides' shading normals lie within coplanar_degrees of each other at both
// ends; walled, coplanar pieces that some triangle of `walls` (the scene of m's geometry) separates
// (seams.hpp, seam_wall_points). Precondition: indices in range, positions finite. Cost: O(E log E)
// for E edges, plus the T-junction search (a grid of the vertices, about median-edge-length cells),
// plus seam_wall_points rays per coplanar piece.
std::vector<seam_piece> find_seams(const seam_mesh& m, float coplanar_degrees, const scene& walls);

// The seams of a bake_lightmap input (one page: the whole width x height lightmap). Cost: as
// find_seams, plus a copy of the corners' UVs.
std::vector<seam_piece> lightmap_seams(const bake_input& in, int width, int height, float coplanar_degrees, const scene& walls);

// The bilinear footprint of texel coordinates t (texel units of the page) in a page: four texel
// indices in the grid of width `grid_width` that holds the page at r, clamp-to-edge within the
// page, and their weights (summing to 1).
struct footprint {
  std::array<std::size_t, 4> texel{};
  std::array<float, 4> weight{};
};

inline footprint bilinear_footprint(const page_rect& r, std::size_t grid_width, const glm::vec2& t) {
  // Beyond the page's border every lookup reads its edge: coordinates clamped first (so that even
  // huge ones give finite weights).
  const double x = std::clamp(double(t.x) - 0.5, -1.0, double(r.width)), y = std::clamp(double(t.y) - 0.5, -1.0, double(r.height));
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const auto fx = float(x - fx0), fy = float(y - fy0);
  // Clamped in double before the conversion: coordinates far outside stay in int range.
  const auto clamp_to = [](double v, int n) { return std::size_t(std::clamp(v, 0.0, double(n - 1))); };
  const std::size_t x0 = clamp_to(fx0, r.width), x1 = clamp_to(fx0 + 1.0, r.width);
  const std::size_t y0 = clamp_to(fy0, r.height), y1 = clamp_to(fy0 + 1.0, r.height);
  const std::size_t ox = std::size_t(r.x), oy = std::size_t(r.y);
  footprint f;
  f.texel = {(oy + y0) * grid_width + ox + x0, (oy + y0) * grid_width + ox + x1, (oy + y1) * grid_width + ox + x0,
             (oy + y1) * grid_width + ox + x1};
  f.weight = {(1.0f - fx) * (1.0f - fy), fx * (1.0f - fy), (1.0f - fx) * fy, fx * fy};
  return f;
}

// The luminance of an RGB triple (seams.hpp's Y: 0.2126 R + 0.7152 G + 0.0722 B), in double.
inline double rgb_luminance(const float* rgb) {
  return 0.2126 * double(rgb[0]) + 0.7152 * double(rgb[1]) + 0.0722 * double(rgb[2]);
}

// The luminance of a bilinear lookup through footprint f, texel k's RGB at rgb_of(k).
template <class F>
double bilinear_luminance(const footprint& f, F&& rgb_of) {
  double y = 0.0;
  for (std::size_t k = 0; k < 4; ++k) y += double(f.weight[k]) * rgb_luminance(rgb_of(f.texel[k]));
  return y;
}

}  // namespace hemilight::bake_detail
