// Step 1 of the unwrapper (unwrap_internal.hpp): weld_and_link, as the chain weld_vertices,
// triangle_normals, link_edges.
#include "unwrap_internal.hpp"

#include <algorithm>
#include <array>
#include <cstring>

namespace hemilight::unwrap_detail {

namespace {

// A position's bits, -0 read as +0 (so the two weld).
std::array<std::uint32_t, 3> position_key(const glm::vec3& p) {
  std::array<std::uint32_t, 3> k;
  std::memcpy(k.data(), &p, sizeof k);
  for (std::uint32_t& b : k)
    if (b == 0x80000000u) b = 0;
  return k;
}

std::uint64_t mix(const std::array<std::uint32_t, 3>& k) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (std::uint32_t b : k) {
    h ^= b;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 31;
  }
  return h;
}

// Welded vertices numbered in order of first appearance: an open-addressing table of the
// positions' bits. Cost: O(V) expected.
void weld_vertices(const mesh_view& m, welded_mesh& w) {
  std::size_t capacity = 16;
  while (capacity < 2 * m.vertex_count) capacity *= 2;
  std::vector<std::uint32_t> slot(capacity, none);       // welded vertex, or none
  std::vector<std::array<std::uint32_t, 3>> keys;        // per welded vertex
  w.weld.resize(m.vertex_count);
  for (std::size_t v = 0; v < m.vertex_count; ++v) {
    const std::array<std::uint32_t, 3> k = position_key(m.positions[v]);
    std::size_t s = std::size_t(mix(k)) & (capacity - 1);
    while (slot[s] != none && keys[slot[s]] != k) s = (s + 1) & (capacity - 1);
    if (slot[s] == none) {
      slot[s] = std::uint32_t(keys.size());
      keys.push_back(k);
    }
    w.weld[v] = slot[s];
  }
  w.welded_count = keys.size();
}

// Unit normals and areas in double; degenerate triangles flagged (scene.hpp's rule).
void triangle_normals(const mesh_view& m, welded_mesh& w) {
  const std::size_t T = m.triangle_count;
  w.normal.assign(T, glm::dvec3(0.0));
  w.area.assign(T, 0.0);
  w.degenerate.assign(T, 0);
  for (std::size_t t = 0; t < T; ++t) {
    const std::uint32_t* idx = m.indices + 3 * t;
    if (is_degenerate_triangle(m.positions[idx[0]], m.positions[idx[1]], m.positions[idx[2]])) {
      w.degenerate[t] = 1;
      ++w.degenerate_count;
      continue;
    }
    const glm::dvec3 n = glm::cross(m.corner(t, 1) - m.corner(t, 0), m.corner(t, 2) - m.corner(t, 0));
    const double len = glm::length(n);
    w.normal[t] = n / len;
    w.area[t] = 0.5 * len;
  }
}

struct edge_entry {
  std::uint64_t key;  // (smaller welded vertex << 32) | larger
  std::uint32_t edge; // 3 t + e
};

// Stable LSD radix sort by key (16-bit digits, as many as the largest key needs): equal keys keep
// the order of their edges.
void sort_by_key(std::vector<edge_entry>& entries) {
  std::uint64_t largest = 0;
  for (const edge_entry& e : entries) largest = std::max(largest, e.key);
  std::vector<edge_entry> scratch(entries.size());
  for (int shift = 0; shift < 64 && (largest >> shift) != 0; shift += 16) {
    std::vector<std::size_t> count(65537, 0);
    for (const edge_entry& e : entries) ++count[((e.key >> shift) & 0xffff) + 1];
    for (std::size_t d = 1; d < count.size(); ++d) count[d] += count[d - 1];
    for (const edge_entry& e : entries) scratch[count[(e.key >> shift) & 0xffff]++] = e;
    entries.swap(scratch);
  }
}

// Edges of non-degenerate triangles grouped by their welded vertex pair: a pair of opposite
// edges links its two triangles; every group is a ring in same_edge.
void link_edges(const mesh_view& m, welded_mesh& w) {
  const std::size_t T = m.triangle_count;
  w.neighbour.assign(3 * T, none);
  w.same_edge.assign(3 * T, none);
  std::vector<edge_entry> entries;
  entries.reserve(3 * (T - w.degenerate_count));
  for (std::size_t t = 0; t < T; ++t) {
    if (w.degenerate[t]) continue;
    for (int e = 0; e < 3; ++e) {
      const std::uint64_t a = w.welded(m, t, e), b = w.welded(m, t, (e + 1) % 3);
      entries.push_back({(std::min(a, b) << 32) | std::max(a, b), std::uint32_t(3 * t + std::size_t(e))});
    }
  }
  sort_by_key(entries);
  const auto from = [&](std::uint32_t edge) { return w.welded(m, edge / 3, int(edge % 3)); };
  for (std::size_t i = 0; i < entries.size();) {
    std::size_t j = i + 1;
    while (j < entries.size() && entries[j].key == entries[i].key) ++j;
    for (std::size_t k = i; k < j; ++k) w.same_edge[entries[k].edge] = entries[k + 1 < j ? k + 1 : i].edge;
    if (j - i == 2 && from(entries[i].edge) != from(entries[i + 1].edge)) {
      w.neighbour[entries[i].edge] = entries[i + 1].edge;
      w.neighbour[entries[i + 1].edge] = entries[i].edge;
    }
    i = j;
  }
}

}  // namespace

welded_mesh weld_and_link(const mesh_view& m) {
  welded_mesh w;
  weld_vertices(m, w);
  triangle_normals(m, w);
  link_edges(m, w);
  return w;
}

}  // namespace hemilight::unwrap_detail
