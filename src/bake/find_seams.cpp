// find_seams (seam_search.hpp): the seam pieces of a lightmap, as the chain of named steps
//   usable_triangles -> collect_edges -> shared_endpoint_pairs + t_junction_pairs -> make_pieces
#include "seam_search.hpp"

#include "hemilight/rays.hpp"
#include "hemilight/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>
#include <utility>

namespace hemilight::bake_detail {

namespace {

// A triangle with texels, as the search reads it; usable = false for degenerate triangles
// (is_degenerate_triangle), triangles without UV area and triangles without texels.
struct tri_info {
  bool usable = false;
  glm::vec3 face_normal{0.0f};
};

std::vector<tri_info> usable_triangles(const seam_mesh& m) {
  std::vector<tri_info> out(m.triangle_count);
  for (std::size_t t = 0; t < m.triangle_count; ++t) {
    const int page = m.triangle_page ? m.triangle_page[t] : 0;
    if (page < 0 || std::size_t(page) >= m.pages.size()) continue;
    const glm::vec3 &f0 = m.positions[m.indices[3 * t]], &f1 = m.positions[m.indices[3 * t + 1]], &f2 = m.positions[m.indices[3 * t + 2]];
    if (is_degenerate_triangle(f0, f1, f2)) continue;
    const glm::dvec3 p0(f0), p1(f1), p2(f2);
    const glm::dvec3 c = glm::cross(p1 - p0, p2 - p0);
    const double area2 = glm::length(c);
    const page_rect& r = m.pages[std::size_t(page)];
    const glm::dvec2 size(r.width, r.height);
    const glm::dvec2 u0 = glm::dvec2(m.corner_uvs[3 * t]) * size, u1 = glm::dvec2(m.corner_uvs[3 * t + 1]) * size,
                     u2 = glm::dvec2(m.corner_uvs[3 * t + 2]) * size;
    const double uv_area2 = std::fabs((u1.x - u0.x) * (u2.y - u0.y) - (u1.y - u0.y) * (u2.x - u0.x));
    // No UV area: the baker's rule (at most 1e-12 of the UV square; coverage.cpp) gives no texels.
    if (!(uv_area2 > 2e-12 * size.x * size.y)) continue;
    out[t].usable = true;
    out[t].face_normal = glm::vec3(c / area2);
  }
  return out;
}

struct edge {
  std::uint32_t tri;
  std::uint8_t corner;  // from corner `corner` to corner (corner + 1) % 3
};

glm::vec3 edge_start(const seam_mesh& m, const edge& e) { return m.positions[m.indices[3 * std::size_t(e.tri) + e.corner]]; }
glm::vec3 edge_end(const seam_mesh& m, const edge& e) {
  return m.positions[m.indices[3 * std::size_t(e.tri) + std::size_t((e.corner + 1) % 3)]];
}

std::vector<edge> collect_edges(const std::vector<tri_info>& tris) {
  std::vector<edge> edges;
  for (std::size_t t = 0; t < tris.size(); ++t)
    if (tris[t].usable)
      for (std::uint8_t c = 0; c < 3; ++c) edges.push_back(edge{std::uint32_t(t), c});
  return edges;
}

// A position's bits with -0 read as +0: bit-identical positions are the same vertex.
using position_key = std::array<std::uint32_t, 3>;
position_key key_of(const glm::vec3& p) {
  position_key k;
  for (int c = 0; c < 3; ++c) {
    const float v = p[c] == 0.0f ? 0.0f : p[c];
    std::memcpy(&k[std::size_t(c)], &v, sizeof v);
  }
  return k;
}

// Pairs of edges (indices into `edges`, lower first) with bit-identical endpoints.
std::vector<std::pair<std::uint32_t, std::uint32_t>> shared_endpoint_pairs(const seam_mesh& m, const std::vector<edge>& edges) {
  using edge_key = std::array<std::uint32_t, 6>;
  std::vector<std::pair<edge_key, std::uint32_t>> keyed(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    position_key a = key_of(edge_start(m, edges[i])), b = key_of(edge_end(m, edges[i]));
    if (b < a) std::swap(a, b);
    edge_key k;
    std::copy(a.begin(), a.end(), k.begin());
    std::copy(b.begin(), b.end(), k.begin() + 3);
    keyed[i] = {k, std::uint32_t(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::size_t lo = 0; lo < keyed.size();) {
    std::size_t hi = lo + 1;
    while (hi < keyed.size() && keyed[hi].first == keyed[lo].first) ++hi;
    for (std::size_t i = lo; i < hi; ++i)
      for (std::size_t j = i + 1; j < hi; ++j)
        if (edges[keyed[i].second].tri != edges[keyed[j].second].tri)
          pairs.emplace_back(std::min(keyed[i].second, keyed[j].second), std::max(keyed[i].second, keyed[j].second));
    lo = hi;
  }
  return pairs;
}

// The distinct endpoint positions of the edges, each with the edges that start or end there.
struct vertex_table {
  std::vector<glm::vec3> position;
  std::vector<std::vector<std::uint32_t>> edges;
};

vertex_table make_vertex_table(const seam_mesh& m, const std::vector<edge>& edges) {
  std::vector<std::pair<position_key, std::uint32_t>> ends;
  ends.reserve(2 * edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    ends.emplace_back(key_of(edge_start(m, edges[i])), std::uint32_t(i));
    ends.emplace_back(key_of(edge_end(m, edges[i])), std::uint32_t(i));
  }
  std::sort(ends.begin(), ends.end());
  vertex_table v;
  for (std::size_t lo = 0; lo < ends.size();) {
    std::size_t hi = lo + 1;
    while (hi < ends.size() && ends[hi].first == ends[lo].first) ++hi;
    glm::vec3 p;
    std::memcpy(&p, ends[lo].first.data(), sizeof p);
    v.position.push_back(p);
    v.edges.emplace_back();
    for (std::size_t i = lo; i < hi; ++i) v.edges.back().push_back(ends[i].second);
    lo = hi;
  }
  return v;
}

// A uniform grid of the vertices (cells of about the median edge length) for point-on-segment
// queries.
class vertex_grid {
 public:
  vertex_grid(const vertex_table& v, float cell) : cell_(cell), count_(v.position.size()) {
    for (std::size_t i = 0; i < v.position.size(); ++i) cells_[key(cell_of(v.position[i]))].push_back(std::uint32_t(i));
  }
  // Calls f(vertex) for every vertex in the cells that a box lo..hi touches, or, when that box
  // spans many more cells than the segment p..q passes (a long diagonal edge), in the 27 cells
  // around points every half cell along the segment (vertices may repeat).
  template <class F>
  void near_segment(const glm::vec3& p, const glm::vec3& q, float pad, F&& f) const {
    const glm::vec3 lo = glm::min(p, q) - pad, hi = glm::max(p, q) + pad;
    const glm::dvec3 a = cell_of(lo), b = cell_of(hi);
    const double box = (b.x - a.x + 1) * (b.y - a.y + 1) * (b.z - a.z + 1);
    const double steps = std::ceil(2.0 * double(glm::length(q - p)) / double(cell_)) + 1.0;
    // An edge far longer than the cells (a huge triangle among small ones): every vertex, once.
    if (!(std::min(box, 27.0 * (steps + 1.0)) <= double(count_))) {
      for (std::size_t i = 0; i < count_; ++i) f(std::uint32_t(i));
      return;
    }
    if (box <= 27.0 * (steps + 1.0)) {
      for (double z = a.z; z <= b.z; ++z)
        for (double y = a.y; y <= b.y; ++y)
          for (double x = a.x; x <= b.x; ++x) visit(glm::dvec3(x, y, z), f);
      return;
    }
    for (double s = 0; s <= steps; ++s) {
      const glm::dvec3 c = cell_of(p + float(s / steps) * (q - p));
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) visit(c + glm::dvec3(dx, dy, dz), f);
    }
  }

 private:
  glm::dvec3 cell_of(const glm::vec3& p) const { return glm::floor(glm::dvec3(p) / double(cell_)); }
  static std::uint64_t key(const glm::dvec3& c) {
    // Cells far from the origin share keys now and then: only more candidates, each tested.
    const auto part = [](double v) { return std::uint64_t(std::int64_t(std::fmod(v, 2097152.0))) & 0x1fffffu; };
    return part(c.x) | (part(c.y) << 21) | (part(c.z) << 42);
  }
  template <class F>
  void visit(const glm::dvec3& c, F&& f) const {
    const auto it = cells_.find(key(c));
    if (it != cells_.end())
      for (std::uint32_t v : it->second) f(v);
  }
  float cell_;
  std::size_t count_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

float median_edge_length(const seam_mesh& m, const std::vector<edge>& edges) {
  std::vector<float> len(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) len[i] = glm::length(edge_end(m, edges[i]) - edge_start(m, edges[i]));
  std::nth_element(len.begin(), len.begin() + std::ptrdiff_t(len.size() / 2), len.end());
  return len[len.size() / 2];
}

// Distance of p from the line through a with direction d (|d| > 0), in double.
double line_distance(const glm::dvec3& a, const glm::dvec3& d, const glm::dvec3& p) {
  const glm::dvec3 ap = p - a;
  return glm::length(ap - d * (glm::dot(ap, d) / glm::dot(d, d)));
}

// Pairs of collinear edges that overlap where an endpoint of one lies inside the other
// (T-junctions; seam_position_tolerance): for each edge, the vertices inside it, and each edge
// at such a vertex whose other end lies on the same line.
std::vector<std::pair<std::uint32_t, std::uint32_t>> t_junction_pairs(const seam_mesh& m, const std::vector<edge>& edges) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  if (edges.empty()) return pairs;
  const vertex_table v = make_vertex_table(m, edges);
  const float cell = median_edge_length(m, edges);
  if (!(cell > 0.0f) || !std::isfinite(cell)) return pairs;
  const vertex_grid grid(v, cell);
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const glm::vec3 pf = edge_start(m, edges[i]), qf = edge_end(m, edges[i]);
    const glm::dvec3 p(pf), d = glm::dvec3(qf) - p;
    const double len = glm::length(d), tol = double(seam_position_tolerance) * len;
    if (!(len > 0.0)) continue;
    const position_key kp = key_of(pf), kq = key_of(qf);
    grid.near_segment(pf, qf, float(tol), [&](std::uint32_t vi) {
      const glm::vec3 x = v.position[vi];
      const position_key kx = key_of(x);
      if (kx == kp || kx == kq) return;
      const double s = glm::dot(glm::dvec3(x) - p, d) / (len * len);
      if (!(s * len > tol && (1.0 - s) * len > tol) || line_distance(p, d, glm::dvec3(x)) > tol) return;
      for (std::uint32_t j : v.edges[vi]) {
        if (edges[j].tri == edges[i].tri) continue;
        const glm::vec3 o = key_of(edge_start(m, edges[j])) == kx ? edge_end(m, edges[j]) : edge_start(m, edges[j]);
        if (line_distance(p, d, glm::dvec3(o)) > tol) continue;
        pairs.emplace_back(std::min(std::uint32_t(i), j), std::max(std::uint32_t(i), j));
      }
    });
  }
  return pairs;
}

// The shading normal of corner c of triangle t: the vertex normal (normalised) or the face normal
// (also where the vertex normal has no direction).
glm::dvec3 corner_normal(const seam_mesh& m, const std::vector<tri_info>& tris, std::uint32_t t, int c) {
  if (m.normals) {
    const glm::dvec3 n(m.normals[m.indices[3 * std::size_t(t) + std::size_t(c)]]);
    const double l = glm::length(n);
    if (l > 1e-20) return n / l;
  }
  return glm::dvec3(tris[t].face_normal);
}

// Side of edge e at edge parameters s0, s1 (0 = its start, 1 = its end).
seam_side make_side(const seam_mesh& m, const std::vector<tri_info>& tris, const edge& e, double s0, double s1) {
  const std::size_t t = e.tri;
  const int c0 = e.corner, c1 = (e.corner + 1) % 3;
  seam_side side;
  side.triangle = e.tri;
  side.page = m.triangle_page ? m.triangle_page[t] : 0;
  const page_rect& r = m.pages[std::size_t(side.page)];
  const glm::dvec2 size(r.width, r.height);
  const glm::dvec2 u0 = glm::dvec2(m.corner_uvs[3 * t + std::size_t(c0)]), u1 = glm::dvec2(m.corner_uvs[3 * t + std::size_t(c1)]);
  side.t0 = glm::vec2((u0 + s0 * (u1 - u0)) * size);
  side.t1 = glm::vec2((u0 + s1 * (u1 - u0)) * size);
  // Inward: the edge's perpendicular (texel units) on the side of the third corner.
  const glm::dvec2 along = (u1 - u0) * size, u2 = glm::dvec2(m.corner_uvs[3 * t + std::size_t((c1 + 1) % 3)]) * size;
  glm::dvec2 in(-along.y, along.x);
  if (glm::dot(in, u2 - u0 * size) < 0.0) in = -in;
  const double in_length = glm::length(in);
  side.inward = in_length > 0.0 ? glm::vec2(in / in_length) : glm::vec2(0.0f);
  const glm::dvec3 n0 = corner_normal(m, tris, e.tri, c0), n1 = corner_normal(m, tris, e.tri, c1);
  const auto normal_at = [&](double s) {
    const glm::dvec3 n = n0 + s * (n1 - n0);
    const double l = glm::length(n);
    return l > 1e-12 ? glm::vec3(n / l) : tris[t].face_normal;
  };
  side.n0 = normal_at(s0);
  side.n1 = normal_at(s1);
  const glm::vec3 p[3] = {m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]};
  const glm::vec2 uv[3] = {m.corner_uvs[3 * t], m.corner_uvs[3 * t + 1], m.corner_uvs[3 * t + 2]};
  const frame f = lightmap_tangent_frame(p, uv, normal_at(0.5 * (s0 + s1)));
  side.tangent = f.t;
  side.bitangent = f.b;
  return side;
}

// The piece two edges share (their overlap along the first), or false when they only touch or
// their UVs agree within seam_uv_tolerance at both ends in one page (one chart).
bool make_piece(const seam_mesh& m, const std::vector<tri_info>& tris, const edge& ea, const edge& eb, double cos_max,
                seam_piece& out) {
  const glm::dvec3 p(edge_start(m, ea)), d = glm::dvec3(edge_end(m, ea)) - p;
  const glm::dvec3 q(edge_start(m, eb)), e = glm::dvec3(edge_end(m, eb)) - q;
  const double dd = glm::dot(d, d), ee = glm::dot(e, e);
  const double sq = glm::dot(q - p, d) / dd, sr = glm::dot(q + e - p, d) / dd;
  const double lo = std::max(0.0, std::min(sq, sr)), hi = std::min(1.0, std::max(sq, sr));
  if (!((hi - lo) * std::sqrt(dd) > double(seam_position_tolerance) * std::min(std::sqrt(dd), std::sqrt(ee)))) return false;
  const glm::dvec3 x0 = p + lo * d, x1 = p + hi * d;
  const auto along_b = [&](const glm::dvec3& x) { return std::clamp(glm::dot(x - q, e) / ee, 0.0, 1.0); };
  out.a = make_side(m, tris, ea, lo, hi);
  out.b = make_side(m, tris, eb, along_b(x0), along_b(x1));
  if (out.a.page == out.b.page && glm::length(out.a.t0 - out.b.t0) <= seam_uv_tolerance &&
      glm::length(out.a.t1 - out.b.t1) <= seam_uv_tolerance)
    return false;
  out.p0 = glm::vec3(x0);
  out.p1 = glm::vec3(x1);
  out.length_texels = 0.5f * (glm::length(out.a.t1 - out.a.t0) + glm::length(out.b.t1 - out.b.t0));
  out.coplanar = double(glm::dot(out.a.n0, out.b.n0)) >= cos_max && double(glm::dot(out.a.n1, out.b.n1)) >= cos_max;
  return true;
}

// A point half a texel from the point x of side s's edge, perpendicular to the edge in the plane
// of its triangle and towards it (past the triangle when it is thinner: the chart goes on there, or
// the segment still shows what stands on the seam), lifted off its face by `lift` x that distance.
glm::dvec3 inside_point(const seam_mesh& m, const std::vector<tri_info>& tris, const seam_side& s, const glm::dvec3& x,
                        const glm::dvec3& edge_dir, double texel_world, double lift) {
  const std::size_t t = s.triangle;
  const glm::dvec3 c = (glm::dvec3(m.positions[m.indices[3 * t]]) + glm::dvec3(m.positions[m.indices[3 * t + 1]]) +
                        glm::dvec3(m.positions[m.indices[3 * t + 2]])) / 3.0;
  glm::dvec3 in = c - x;
  in -= edge_dir * glm::dot(in, edge_dir);  // perpendicular to the edge, towards the triangle
  const double h = glm::length(in);
  if (!(h > 0.0)) return x;
  const double d = 0.5 * texel_world;
  return x + in * (d / h) + glm::dvec3(tris[t].face_normal) * (lift * d);
}

// Whether a triangle of `walls` separates the two sides of a near-coplanar piece (seams.hpp).
bool walled_piece(const seam_mesh& m, const std::vector<tri_info>& tris, const seam_piece& p, const scene& walls) {
  const glm::dvec3 p0(p.p0), p1(p.p1);
  const double world = glm::length(p1 - p0);
  if (!(world > 0.0) || !(p.length_texels > 0.0f)) return false;
  const glm::dvec3 dir = (p1 - p0) / world;
  const double texel_world = world / double(p.length_texels);
  // Lifted by 1% plus tan(theta / 2) of the inward distance, theta the angle between the faces: the
  // segment clears the two faces' own ridge (smooth-shaded faces may meet at any angle).
  const double cos_theta = std::clamp(double(glm::dot(tris[p.a.triangle].face_normal, tris[p.b.triangle].face_normal)), -1.0, 1.0);
  const double lift = 0.01 + std::tan(0.5 * std::min(std::acos(cos_theta), 3.0));
  for (int k = 0; k < seam_wall_points; ++k) {
    const double s = (double(k) + 0.5) / double(seam_wall_points);
    const glm::dvec3 x = p0 + s * (p1 - p0);
    const glm::dvec3 a = inside_point(m, tris, p.a, x, dir, texel_world, lift),
                     b = inside_point(m, tris, p.b, x, dir, texel_world, lift);
    if (occluded(walls, glm::vec3(a), glm::vec3(b - a), 1.0f)) return true;
  }
  return false;
}

}  // namespace

std::vector<seam_piece> find_seams(const seam_mesh& m, float coplanar_degrees, const scene& walls) {
  const std::vector<tri_info> tris = usable_triangles(m);
  const std::vector<edge> edges = collect_edges(tris);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs = shared_endpoint_pairs(m, edges);
  const std::vector<std::pair<std::uint32_t, std::uint32_t>> t_pairs = t_junction_pairs(m, edges);
  pairs.insert(pairs.end(), t_pairs.begin(), t_pairs.end());
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  const double cos_max = std::cos(double(coplanar_degrees) * 3.14159265358979323846 / 180.0);
  std::vector<seam_piece> pieces;
  for (const auto& [i, j] : pairs) {
    seam_piece piece;
    if (!make_piece(m, tris, edges[i], edges[j], cos_max, piece)) continue;
    piece.walled = piece.coplanar && walled_piece(m, tris, piece, walls);
    pieces.push_back(piece);
  }
  return pieces;
}

std::vector<seam_piece> lightmap_seams(const bake_input& in, int width, int height, float coplanar_degrees, const scene& walls) {
  const scene_desc& d = in.scene;
  std::vector<glm::vec2> uvs(3 * d.triangle_count);
  for (std::size_t i = 0; i < uvs.size(); ++i) uvs[i] = d.lightmap_uvs[d.indices[i]];
  seam_mesh m;
  m.positions = d.positions;
  m.vertex_count = d.vertex_count;
  m.indices = d.indices;
  m.triangle_count = d.triangle_count;
  m.normals = in.normals;
  m.corner_uvs = uvs.data();
  m.pages = {page_rect{0, 0, width, height}};
  return find_seams(m, coplanar_degrees, walls);
}

}  // namespace hemilight::bake_detail
