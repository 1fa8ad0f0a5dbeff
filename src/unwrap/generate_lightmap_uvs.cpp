// generate_lightmap_uvs (unwrap.hpp): the scene_mesh form of unwrap_lightmap, and the shelf
// packer of planar charts kept for the built-in scenes.
#include "hemilight/unwrap.hpp"

#include "hemilight/error.hpp"
#include "hemilight/geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <string>

namespace hemilight {

namespace {

using vertex_key = std::array<std::uint32_t, 3>;  // position bits: shared edges are bit-identical

vertex_key key_of(const glm::vec3& p) {
  vertex_key k;
  std::memcpy(k.data(), &p, sizeof k);
  return k;
}

std::size_t find_root(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

struct chart {
  std::vector<std::size_t> triangles;
  frame basis{};
  glm::dvec2 lo{0.0}, hi{0.0};  // extent in the chart plane (scene units)
  int x = 0, y = 0;             // texel origin after packing
};

// Shelf packing of the charts at `density` texels per unit; false if they do not fit.
bool pack(std::vector<chart>& charts, const std::vector<std::size_t>& order, double density, int size, int padding) {
  int x = padding, y = padding, shelf = 0;
  for (std::size_t c : order) {
    chart& ch = charts[c];
    const int w = int(std::ceil((ch.hi.x - ch.lo.x) * density)), h = int(std::ceil((ch.hi.y - ch.lo.y) * density));
    if (w + 2 * padding > size || h + 2 * padding > size) return false;
    if (x + w + padding > size) {  // next shelf
      x = padding;
      y += shelf + padding;
      shelf = 0;
    }
    if (y + h + padding > size) return false;
    ch.x = x;
    ch.y = y;
    x += w + padding;
    shelf = std::max(shelf, h);
  }
  return true;
}

}  // namespace

unwrap_result generate_lightmap_uvs(scene_mesh& mesh, const unwrap_options& options) {
  unwrap_result r = unwrap_lightmap(mesh.positions.data(), mesh.positions.size(), mesh.indices.data(), mesh.triangle_count(), options);
  std::vector<glm::vec3> positions(r.vertex_source.size());
  for (std::size_t i = 0; i < positions.size(); ++i) positions[i] = mesh.positions[r.vertex_source[i]];
  mesh.positions = std::move(positions);
  mesh.lightmap_uvs = r.uvs;
  mesh.indices = r.indices;
  return r;
}

void generate_lightmap_uvs(scene_mesh& mesh, int size, int padding) {
  if (size < 8) throw_invalid_argument("generate_lightmap_uvs: size " + std::to_string(size) + " must be >= 8");
  if (padding < 0 || 4 * padding >= size)
    throw_invalid_argument("generate_lightmap_uvs: padding " + std::to_string(padding) + " must be in [0, size / 4)");
  const std::size_t tri_count = mesh.triangle_count();
  std::vector<glm::dvec3> normal(tri_count, glm::dvec3(0.0));
  for (std::size_t i = 0; i < tri_count; ++i) {
    const glm::dvec3 a(mesh.positions[mesh.indices[3 * i]]), b(mesh.positions[mesh.indices[3 * i + 1]]),
        c(mesh.positions[mesh.indices[3 * i + 2]]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double len = glm::length(n);
    if (len > 0.0) normal[i] = n / len;
  }
  // Charts: union of triangles that share an edge (by position) and face the same way.
  std::vector<std::size_t> parent(tri_count);
  std::iota(parent.begin(), parent.end(), std::size_t(0));
  std::map<std::pair<vertex_key, vertex_key>, std::size_t> first_with_edge;
  for (std::size_t i = 0; i < tri_count; ++i) {
    if (normal[i] == glm::dvec3(0.0)) continue;  // degenerate: a chart of its own
    for (int e = 0; e < 3; ++e) {
      vertex_key a = key_of(mesh.positions[mesh.indices[3 * i + std::size_t(e)]]);
      vertex_key b = key_of(mesh.positions[mesh.indices[3 * i + std::size_t((e + 1) % 3)]]);
      if (b < a) std::swap(a, b);
      const auto [it, inserted] = first_with_edge.emplace(std::make_pair(a, b), i);
      if (!inserted && glm::dot(normal[it->second], normal[i]) > 0.9999) {
        const std::size_t ra = find_root(parent, it->second), rb = find_root(parent, i);
        if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
      }
    }
  }
  std::vector<chart> charts;
  std::vector<std::size_t> chart_of_root(tri_count, SIZE_MAX);
  for (std::size_t i = 0; i < tri_count; ++i) {
    const std::size_t root = find_root(parent, i);
    if (chart_of_root[root] == SIZE_MAX) {
      chart_of_root[root] = charts.size();
      charts.emplace_back();
      const glm::dvec3 n = normal[root] == glm::dvec3(0.0) ? glm::dvec3(0, 0, 1) : normal[root];
      charts.back().basis = make_frame(glm::vec3(n));
    }
    charts[chart_of_root[root]].triangles.push_back(i);
  }
  double total_area = 0.0;
  for (chart& ch : charts) {
    ch.lo = glm::dvec2(std::numeric_limits<double>::infinity());
    ch.hi = -ch.lo;
    for (std::size_t t : ch.triangles)
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3 p(mesh.positions[mesh.indices[3 * t + std::size_t(k)]]);
        const glm::dvec2 q(glm::dot(p, glm::dvec3(ch.basis.t)), glm::dot(p, glm::dvec3(ch.basis.b)));
        ch.lo = glm::min(ch.lo, q);
        ch.hi = glm::max(ch.hi, q);
      }
    total_area += (ch.hi.x - ch.lo.x) * (ch.hi.y - ch.lo.y);
  }
  // Tallest first (ties: chart order): the usual shelf heuristic, deterministic.
  std::vector<std::size_t> order(charts.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return charts[a].hi.y - charts[a].lo.y > charts[b].hi.y - charts[b].lo.y;
  });
  // Largest density that packs: bisection between 0 and the density that fills the map exactly.
  double lo = 0.0, hi = total_area > 0.0 ? double(size) / std::sqrt(total_area) * 1.01 : 1.0;
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (pack(charts, order, mid, size, padding))
      lo = mid;
    else
      hi = mid;
  }
  if (!pack(charts, order, lo, size, padding))
    throw error(status::internal, "generate_lightmap_uvs: the charts do not pack at density 0");
  // New vertices: one per (chart, old vertex).
  std::vector<glm::vec3> positions;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices(mesh.indices.size());
  for (const chart& ch : charts) {
    std::map<std::uint32_t, std::uint32_t> remap;
    for (std::size_t t : ch.triangles)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t old = mesh.indices[3 * t + std::size_t(k)];
        auto [it, inserted] = remap.emplace(old, std::uint32_t(positions.size()));
        if (inserted) {
          const glm::vec3 p = mesh.positions[old];
          const glm::dvec2 q(glm::dot(glm::dvec3(p), glm::dvec3(ch.basis.t)), glm::dot(glm::dvec3(p), glm::dvec3(ch.basis.b)));
          const glm::dvec2 texel = glm::dvec2(ch.x, ch.y) + (q - ch.lo) * lo;
          positions.push_back(p);
          uvs.push_back(glm::clamp(glm::vec2(texel / double(size)), 0.0f, 1.0f));
        }
        indices[3 * t + std::size_t(k)] = it->second;
      }
  }
  mesh.positions = std::move(positions);
  mesh.lightmap_uvs = std::move(uvs);
  mesh.indices = std::move(indices);
}

}  // namespace hemilight
