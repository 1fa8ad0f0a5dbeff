// Exact edge coverage (raster_options::edge_coverage; docs/raster.md, "Exact edge coverage"): the
// partial texels of each drawn triangle, their front-to-back resolve and blend.
#include "hemilight/raster.hpp"
#include "internal.hpp"

#include "../scene/scene_access.hpp"

#include "hemilight/cubemap.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>

namespace hemilight {

using namespace raster_detail;

// ---------------------------------------------------------------------------------------------
// Exact edge coverage (raster_options::edge_coverage; docs/raster.md, "Exact edge coverage")
// ---------------------------------------------------------------------------------------------

namespace {

// The shoelace sums of a polygon given edge by edge (points about the texel's centre): twice its
// area and six times its first moments; weighted(wx, wy) = its weight under the density
// 1 + wx x + wy y (texel units about the centre).
struct polygon_moments {
  double twice = 0.0, mx = 0.0, my = 0.0;
  void add(double ax, double ay, double bx, double by) noexcept {
    const double cross = ax * by - bx * ay;
    twice += cross;
    mx += (ax + bx) * cross;
    my += (ay + by) * cross;
  }
  double weighted(double wx, double wy) const noexcept { return 0.5 * twice + (wx * mx + wy * my) * (1.0 / 6.0); }
};

// The covered part of a texel (as texel_part_inside, below) for one clipping edge
// f0 + gx x + gy y >= 0, with rgx = 1 / gx and
// rgy = 1 / gy (made once per triangle edge; infinite for a zero step, never selected then: a
// side can only be crossed where its step is nonzero): the polygon's shoelace terms, edge by
// edge: the inside part of each side of the square (an interval of it: a half-plane cuts a
// segment once), then the cut itself, from where the boundary leaves the half-plane to where it
// comes back. The crossing of a side runs t = value / (value - next value) along it, and
// value - next value is -gx, -gy, gx, gy on the bottom, right, top and left sides: multiplies by
// the reciprocals, no division. Selects, no branches.
double square_part_inside_one(double f0, double gx, double gy, double rgx, double rgy, double wx, double wy) noexcept {
  const double cx[4] = {-0.5, 0.5, 0.5, -0.5}, cy[4] = {-0.5, -0.5, 0.5, 0.5};  // corners about the centre
  double value[4];
  for (int i = 0; i < 4; ++i) value[i] = f0 + gx * (cx[i] + 0.5) + gy * (cy[i] + 0.5);
  const double step[4] = {-rgx, -rgy, rgx, rgy};  // 1 / (value[i] - value[i + 1]) per side
  polygon_moments sums;
  double out_x = 0.0, out_y = 0.0, in_x = 0.0, in_y = 0.0;  // where the boundary leaves and re-enters
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) & 3;
    const bool in_i = value[i] >= 0.0, in_j = value[j] >= 0.0;
    // (Clamped: the product may round past the side's end, or overflow for a tiny step.)
    const double t = in_i != in_j ? std::min(std::max(value[i] * step[i], 0.0), 1.0) : 0.0;
    const double hx = cx[i] + t * (cx[j] - cx[i]), hy = cy[i] + t * (cy[j] - cy[i]);  // the crossing
    const double ax = in_i ? cx[i] : hx, ay = in_i ? cy[i] : hy;
    const double bx = in_j ? cx[j] : hx, by = in_j ? cy[j] : hy;
    if (in_i || in_j) sums.add(ax, ay, bx, by);
    out_x = in_i && !in_j ? hx : out_x;
    out_y = in_i && !in_j ? hy : out_y;
    in_x = !in_i && in_j ? hx : in_x;
    in_y = !in_i && in_j ? hy : in_y;
  }
  sums.add(out_x, out_y, in_x, in_y);  // (zero when the square is all in or all out)
  return sums.weighted(wx, wy);
}

// One edge of a triangle, for texel_part_inside (texel units, the face's origin): from vertex
// (ax, ay) by (dx, dy), with its edge function's steps across a texel (gx, gy: f = f0 + gx x +
// gy y at (x, y) from the texel's lower left corner, inside where f >= 0) and the reciprocals
// of all four (made once per edge, when it first cuts a texel; unused where a step is zero).
struct clip_edge {
  double ax, ay, dx, dy, gx, gy;
  double rdx, rdy, rgx, rgy;
};

// The covered part of a texel by Green's theorem: the area and first moments of the region
// (the texel square, within the half-planes of the triangle's edges in `clip`, those that cut
// it; the others hold the whole square) are sums over its boundary, counter-clockwise, of the
// shoelace terms of its segments. That boundary is the cutting edges' segments within the
// square (Liang-Barsky: the edge's parameter against the square's four sides) and the square's
// sides within the half-planes (each side's parameter against each edge function, linear along
// it). Every crossing is a product with a reciprocal made per edge: no division, no polygon
// built, few branches, and the branches on the sign of a step are the same for every texel of
// a triangle. (cx, cy): the texel's centre; f0: the edge functions at its lower left corner; the
// moments are about the centre and weighted by the density 1 + wx x + wy y (x, y about the
// centre). The part inside is exact to rounding (~1e-15) for a counter-clockwise triangle;
// the caller gives a triangle that is not counter-clockwise nothing.
double texel_part_inside(const clip_edge (&e)[3], const double (&f0)[3], unsigned clip, double cx, double cy,
                         double wx, double wy) noexcept {
  polygon_moments sums;
  // 1. The cutting edges within the square [-1/2, 1/2]^2 (about the centre).
  for (int k = 0; k < 3; ++k) {
    if (!(clip >> k & 1u)) continue;
    const clip_edge& g = e[k];
    const double ax = g.ax - cx, ay = g.ay - cy;
    double t0 = 0.0, t1 = 1.0;
    // The edge's parameter range within the slab [-1/2, 1/2] of one axis (a: its start on that
    // axis, d: its step, rd = 1 / d); false when it runs parallel to the slab outside it.
    const auto slab = [&](double a, double d, double rd) {
      if (d == 0.0) return std::fabs(a) <= 0.5;
      const double ta = (-0.5 - a) * rd, tb = (0.5 - a) * rd;
      t0 = std::max(t0, std::min(ta, tb));
      t1 = std::min(t1, std::max(ta, tb));
      return true;
    };
    if (!slab(ax, g.dx, g.rdx) || !slab(ay, g.dy, g.rdy)) continue;
    if (t0 < t1) sums.add(ax + t0 * g.dx, ay + t0 * g.dy, ax + t1 * g.dx, ay + t1 * g.dy);
  }
  // 2. The square's sides (bottom, right, top, left) within the cutting half-planes. Side i
  // runs from corner (sx, sy) by (ux, uy), over s in [s0, s1]; along it f_k starts at its
  // value at the corner, with slope m: inside where s >= -v / m (m > 0), s <= -v / m (m < 0),
  // everywhere or nowhere (m = 0). Selects (a zero slope's product is never selected).
  static constexpr double sx[4] = {-0.5, 0.5, 0.5, -0.5}, sy[4] = {-0.5, -0.5, 0.5, 0.5};
  static constexpr double ux[4] = {1.0, 0.0, -1.0, 0.0}, uy[4] = {0.0, 1.0, 0.0, -1.0};
  double s0[4] = {0.0, 0.0, 0.0, 0.0}, s1[4] = {1.0, 1.0, 1.0, 1.0};
  for (int k = 0; k < 3; ++k) {
    if (!(clip >> k & 1u)) continue;
    const clip_edge& g = e[k];
    const double v[4] = {f0[k], f0[k] + g.gx, f0[k] + g.gx + g.gy, f0[k] + g.gy};  // f_k at the corners
    const double m[4] = {g.gx, g.gy, -g.gx, -g.gy};
    const double rm[4] = {g.rgx, g.rgy, -g.rgx, -g.rgy};
    for (int i = 0; i < 4; ++i) {
      const double cut = -v[i] * rm[i];
      s0[i] = m[i] > 0.0 ? std::max(s0[i], cut) : s0[i];
      s1[i] = m[i] < 0.0 ? std::min(s1[i], cut) : (m[i] == 0.0 && v[i] < 0.0 ? -1.0 : s1[i]);
    }
  }
  for (int i = 0; i < 4; ++i)
    if (s0[i] < s1[i]) sums.add(sx[i] + s0[i] * ux[i], sy[i] + s0[i] * uy[i], sx[i] + s1[i] * ux[i], sy[i] + s1[i] * uy[i]);
  return sums.weighted(wx, wy);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Hard edges
//
// Exact coverage matters only where what a texel sees changes across an edge: at a mesh's
// boundary, between different materials, and at a silhouette (one of the edge's triangles faces
// the point, the other not). Across any other edge (two triangles of one material, consistently
// wound, both facing the point or both facing away) the two triangles project on either side of
// it and between them cover both sides: the texel centre's sample is what the texel sees, as far
// as the emission goes (equal on both sides; a texture's value is continuous across the edge up
// to its own seams). So only texels that a hard edge may cross get exact coverage; the others
// keep the centre sample, bit for bit what a render without the option gives.
//
// At bind: the scene's edges are matched by their endpoints' bits (shared edges need not share
// vertex indices). An edge shared by exactly two triangles with opposite windings and equal
// materials whose planes coincide (same unit normal to 1e-10) is never hard and is dropped; one
// whose planes differ (a crease) is hard in a view where the triangles' facings differ (or one
// is seen edge-on); any other edge (one triangle, three or more, equal windings, different
// materials, a degenerate triangle) is hard in every view. Per render: the facings of the
// creases' triangles, then each hard edge's texels on each face are marked (edge_mark_segment),
// conservatively. Cost: O(E log E) at bind for E edges; per render O(creases' triangles +
// candidate edges + the texels hard edges cross).
// ---------------------------------------------------------------------------------------------

namespace {

const glm::vec3& corner(const scene::triangle& t, std::uint32_t k) noexcept {
  return k == 0 ? t.v0 : (k == 1 ? t.v1 : t.v2);
}

// The index of the lowest set bit of a nonzero word.
inline int lowest_bit(std::uint64_t word) noexcept {
#if defined(__GNUC__) || defined(__clang__)
  return __builtin_ctzll(word);
#else
  int i = 0;
  while (!(word & 1u)) {
    word >>= 1;
    ++i;
  }
  return i;
#endif
}

// The cells of the texel's 8 x 8 grid that the part inside the half-planes f_k(x, y) = f0[k] +
// gx[k] x + gy[k] y >= 0 of the edges in `clip` (bit k; x, y in texel units from the texel's
// corner) may touch: bit 8 j + i for cell [i / 8, (i + 1) / 8] x [j / 8, (j + 1) / 8], set when
// every clipping edge's function is >= 0 at some point of the cell (its corner farthest along
// the edge's gradient). Conservative: a part that touches a cell has its bit; two parts with no
// common bit do not overlap (the blend's cheap test). Cost: 64 multiply-adds and compares per
// cutting edge.
std::uint64_t edge_cell_mask(const double (&f0)[3], const double (&gx)[3], const double (&gy)[3],
                             unsigned clip) noexcept {
  std::uint64_t mask = ~std::uint64_t(0);
  for (int k = 0; k < 3; ++k) {
    if (!(clip >> k & 1u)) continue;
    const double ox = gx[k] > 0.0 ? 0.125 : 0.0, oy = gy[k] > 0.0 ? 0.125 : 0.0;  // the farthest corner
    std::uint64_t touched = 0;
    for (int j = 0; j < 8; ++j) {
      const double row = f0[k] + gy[k] * (j * 0.125 + oy);
      unsigned bits = 0;
      for (int i = 0; i < 8; ++i) bits |= static_cast<unsigned>(row + gx[k] * (i * 0.125 + ox) >= 0.0) << i;
      touched |= static_cast<std::uint64_t>(bits) << (8 * j);
    }
    mask &= touched;
  }
  return mask;
}

// Whether two fragments' triangles have an edge on the same line with their insides on opposite
// sides of it (triangles sharing an edge, as a mesh's neighbours do): they cannot overlap. The
// edges' functions are then negative multiples of each other, to rounding (they are computed from
// the same unsnapped endpoints in another order): tested to 1e-9 relative.
bool edge_shared_opposite(const fragment_shape& a, const fragment_shape& b) noexcept {
  for (int k = 0; k < 3; ++k)
    for (int m = 0; m < 3; ++m) {
      const double na = a.norm[k], nb = b.norm[m];
      if (a.gx[k] * b.gx[m] + a.gy[k] * b.gy[m] >= 0.0) continue;  // not opposite (or a zero edge)
      if (std::fabs(a.gx[k] * b.gy[m] - a.gy[k] * b.gx[m]) > 1e-9 * na * nb) continue;  // not parallel
      const double ea = std::fabs(a.f0[k]) + na, eb = std::fabs(b.f0[m]) + nb;
      if (std::fabs(a.f0[k] * nb + b.f0[m] * na) <= 1e-9 * (ea * nb + eb * na)) return true;
    }
  return false;
}

// The part of a texel (the unit square, texel units from its corner) inside both fragments'
// triangles (the half-planes f0 + gx x + gy y >= 0 of the edges that cut it, `clip`, of each):
// the square clipped by them (Sutherland-Hodgman, at most 4 + 6 vertices), then its area and
// first moments about the centre, weighted by the density 1 + wx (x - 1/2) + wy (y - 1/2) as the
// coverages are.
double overlap_part(const fragment_shape& a, const fragment_shape& b, double wx, double wy) noexcept {
  double ax_[10] = {0.0, 1.0, 1.0, 0.0}, ay_[10] = {0.0, 0.0, 1.0, 1.0}, bx_[10], by_[10];
  double *px = ax_, *py = ay_, *qx = bx_, *qy = by_;
  int count = 4;
  for (int e = 0; e < 6 && count >= 3; ++e) {
    const fragment_shape& s = e < 3 ? a : b;
    const int k = e % 3;
    if (!(s.clip >> k & 1u)) continue;
    double value[10];
    for (int i = 0; i < count; ++i) value[i] = s.f0[k] + s.gx[k] * px[i] + s.gy[k] * py[i];
    int out = 0;
    for (int i = 0; i < count; ++i) {
      const int j = i + 1 == count ? 0 : i + 1;
      const bool in_i = value[i] >= 0.0, in_j = value[j] >= 0.0;
      if (in_i) {
        qx[out] = px[i];
        qy[out] = py[i];
        ++out;
      }
      if (in_i != in_j) {
        const double u = value[i] / (value[i] - value[j]);
        qx[out] = px[i] + u * (px[j] - px[i]);
        qy[out] = py[i] + u * (py[j] - py[i]);
        ++out;
      }
    }
    count = out;
    std::swap(px, qx);
    std::swap(py, qy);
  }
  if (count < 3) return 0.0;
  polygon_moments sums;
  for (int i = 0; i < count; ++i) {
    const int j = i + 1 == count ? 0 : i + 1;
    sums.add(px[i] - 0.5, py[i] - 0.5, px[j] - 0.5, py[j] - 0.5);
  }
  if (!(sums.twice > 0.0)) return 0.0;
  return sums.weighted(wx, wy);
}

// The first of `face`'s rows in the per-row hard-texel tables (face 0's N rows, then each side
// face's N / 2).
inline std::size_t face_row_base(int n, int face) noexcept {
  return face == 0 ? 0 : static_cast<std::size_t>(n) + static_cast<std::size_t>(face - 1) * static_cast<std::size_t>(n / 2);
}

// floor(x) and ceil(x) as integers, for |x| < 2^62 (not NaN): a conversion and a compare (the
// library's floor is a call or a long sequence without SSE4.1).
inline std::int64_t floor_int(double x) noexcept {
  const auto i = static_cast<std::int64_t>(x);  // truncates toward zero
  return i - (x < static_cast<double>(i) ? 1 : 0);
}
inline std::int64_t ceil_int(double x) noexcept {
  const auto i = static_cast<std::int64_t>(x);
  return i + (x > static_cast<double>(i) ? 1 : 0);
}

std::uint32_t bits_of(float f) noexcept {
  std::uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

}  // namespace

namespace {

std::shared_ptr<edge_table> build_edge_table(const scene& s) {
  constexpr std::uint32_t no_triangle = hemicube_rasterizer::no_triangle;
  auto table = std::make_shared<edge_table>();
  std::vector<edge_table::candidate>& candidates = table->candidates;
  std::vector<glm::vec4>& planes = table->planes;
  const std::vector<scene::triangle>& tris = s.triangles();
  // Step 1: every edge, keyed by its endpoints' bits in a canonical order.
  struct half_edge {
    std::uint32_t key[6];
    std::uint32_t triangle, k;
    bool forward;  // the edge runs from the smaller key's endpoint to the larger one
  };
  std::vector<half_edge> edges;
  edges.reserve(3 * tris.size());
  for (std::uint32_t i = 0; i < tris.size(); ++i)
    for (std::uint32_t k = 0; k < 3; ++k) {
      const glm::vec3 &a = corner(tris[i], k), &b = corner(tris[i], k == 2 ? 0 : k + 1);
      const std::uint32_t ka[3] = {bits_of(a.x), bits_of(a.y), bits_of(a.z)};
      const std::uint32_t kb[3] = {bits_of(b.x), bits_of(b.y), bits_of(b.z)};
      half_edge h;
      h.forward = std::lexicographical_compare(ka, ka + 3, kb, kb + 3);
      const std::uint32_t* lo = h.forward ? ka : kb;
      const std::uint32_t* hi = h.forward ? kb : ka;
      std::copy(lo, lo + 3, h.key);
      std::copy(hi, hi + 3, h.key + 3);
      h.triangle = i;
      h.k = k;
      edges.push_back(h);
    }
  const auto key_less = [](const half_edge& a, const half_edge& b) {
    if (std::lexicographical_compare(a.key, a.key + 6, b.key, b.key + 6)) return true;
    if (std::lexicographical_compare(b.key, b.key + 6, a.key, a.key + 6)) return false;
    return a.triangle < b.triangle || (a.triangle == b.triangle && a.k < b.k);  // deterministic order
  };
  std::sort(edges.begin(), edges.end(), key_less);

  // Step 2: classify each edge (a run of equal keys).
  const auto unit_normal = [&](const scene::triangle& t) {
    const glm::dvec3 v0(t.v0);
    const glm::dvec3 nrm = glm::cross(glm::dvec3(t.v1) - v0, glm::dvec3(t.v2) - v0);
    const double len = glm::length(nrm);
    return len > 0.0 ? nrm / len : glm::dvec3(0.0);
  };
  const auto same_material = [&](const scene::triangle& a, const scene::triangle& b) {
    const material &ma = s.triangle_material(a.index), &mb = s.triangle_material(b.index);
    return ma.emission == mb.emission && ma.albedo == mb.albedo && ma.two_sided == mb.two_sided;
  };
  std::vector<std::uint32_t> plane_of(tris.size(), no_triangle);
  const auto plane_entry = [&](std::uint32_t i) {
    if (plane_of[i] == no_triangle) {
      const glm::dvec3 nrm = unit_normal(tris[i]);
      plane_of[i] = static_cast<std::uint32_t>(planes.size());
      planes.emplace_back(glm::vec3(nrm), static_cast<float>(glm::dot(nrm, glm::dvec3(tris[i].v0))));
    }
    return plane_of[i];
  };
  for (std::size_t first = 0; first < edges.size();) {
    std::size_t last = first + 1;
    while (last < edges.size() && std::equal(edges[first].key, edges[first].key + 6, edges[last].key)) ++last;
    const half_edge& a = edges[first];
    edge_table::candidate c{a.triangle, a.k, no_triangle, no_triangle};
    if (last - first == 2 && edges[first + 1].forward != a.forward) {
      const half_edge& b = edges[first + 1];
      const scene::triangle &ta = tris[a.triangle], &tb = tris[b.triangle];
      const glm::dvec3 na = unit_normal(ta), nb = unit_normal(tb);
      const bool degenerate = glm::dot(na, na) == 0.0 || glm::dot(nb, nb) == 0.0;
      if (!degenerate && same_material(ta, tb)) {
        if (glm::dot(na, nb) >= 1.0 - 1e-10) {  // one plane: never hard
          first = last;
          continue;
        }
        c.plane_a = plane_entry(a.triangle);
        c.plane_b = plane_entry(b.triangle);
      }
    }
    candidates.push_back(c);
    first = last;
  }
  return table;
}

}  // namespace

const raster_detail::edge_table& raster_detail::edge_table_of(const scene& s) {
  detail::lazy_slot* slot = detail::derived_access::of(s, detail::derived_kind::raster_edges);
  if (!slot->done.load(std::memory_order_acquire))
    std::call_once(slot->once, [&] {
      slot->value = build_edge_table(s);
      slot->done.store(true, std::memory_order_release);
    });
  return *static_cast<const edge_table*>(slot->value.get());
}

// Resets the per-render state before a render of count texels at the given resolution: the
// per-texel lists where the last render used them (all of them if N changed), the hard-texel
// marks and rows.
void raster_detail::rasterizer_impl::edge_prepare(std::size_t count, int resolution) {
  if (edges_.fragment_count.size() != count)
    edges_.fragment_count.assign(count, 0u);
  else
    for (const std::uint32_t t : edges_.fragment_texels) edges_.fragment_count[t] = 0u;
  edges_.fragments.clear();
  edges_.fragment_shapes.clear();
  edges_.fragment_texels.clear();
  edges_.groups.clear();
  if (edges_.whole_z.size() != count) {
    edges_.whole_z.assign(count, 0.0f);
    edges_.whole_id.resize(count);
  } else {
    for (const std::uint32_t t : edges_.hard_texels) edges_.whole_z[t] = 0.0f;
  }
  edges_.words_per_row = (static_cast<std::size_t>(resolution) + 63) / 64;
  edges_.hard_bits.assign(edges_.words_per_row * (static_cast<std::size_t>(resolution) + 4 * static_cast<std::size_t>(resolution / 2)), 0u);
  edges_.silhouette_bits.assign(edges_.hard_bits.size(), 0u);
  edges_.hard_texels.clear();
  edges_.hard_rows.resize(2 * (static_cast<std::size_t>(resolution) + 4 * static_cast<std::size_t>(resolution / 2)));
  for (std::size_t i = 0; i < edges_.hard_rows.size(); i += 2) {
    edges_.hard_rows[i] = resolution;
    edges_.hard_rows[i + 1] = -1;
  }
  edges_.hard_faces = 0;
}

// The slopes of each texel's weight density (edges_.density), once per resolution. The
// integrator weights a texel by the projected solid angle over it, of density (1 + u^2 + v^2)^-2
// on the top face (z = 1) and v (1 + u^2 + v^2)^-2 on the side faces (v = height); relative to
// the centre's and per texel unit, its derivatives there are wx = -4 u / q step and
// wy = -4 v / q step (top) or (1 / v - 4 v / q) step (sides), q = 1 + u^2 + v^2, step = 2 / N.
void raster_detail::rasterizer_impl::edge_make_density() {
  const int n = n_;
  edges_.density.resize(2 * hemicube_texel_count(n));
  for (int face = 0; face < 5; ++face) {
    const int rows = face == 0 ? n : n / 2;
    const std::size_t face_offset = hemicube_face_offset(n, static_cast<hemicube_face>(face));
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < n; ++c) {
        const double u = first_centre_ + texel_step_ * static_cast<double>(c);
        const double v = (face == 0 ? first_centre_ : 0.5 * texel_step_) + texel_step_ * static_cast<double>(r);
        const double q = 1.0 + u * u + v * v;
        const std::size_t texel = face_offset + static_cast<std::size_t>(r) * static_cast<std::size_t>(n) + static_cast<std::size_t>(c);
        edges_.density[2 * texel] = static_cast<float>(-4.0 * u / q * texel_step_);
        edges_.density[2 * texel + 1] = static_cast<float>((face == 0 ? -4.0 * v / q : 1.0 / v - 4.0 * v / q) * texel_step_);
      }
  }
  edges_.density_n = n;
}

void raster_detail::rasterizer_impl::edge_mark_hard(const glm::vec3& position, const frame& basis) {
  if (edges_.density_n != n_) edge_make_density();
  // Facings of the creases' triangles: the sign of the plane's value at the point, 0 within
  // 1e-5 of its scale (seen about edge-on: a silhouette in waiting, so hard).
  const double px = position.x, py = position.y, pz = position.z;
  const double scale = std::fabs(px) + std::fabs(py) + std::fabs(pz);
  for (std::size_t i = 0; i < edges_.table->planes.size(); ++i) {
    const glm::vec4& q = edges_.table->planes[i];
    const double f = static_cast<double>(q.x) * px + static_cast<double>(q.y) * py + static_cast<double>(q.z) * pz -
                     static_cast<double>(q.w);
    const double band = 1e-5 * (scale + std::fabs(static_cast<double>(q.w)));
    edges_.facing[i] = static_cast<std::int8_t>(f > band ? 1 : (f < -band ? -1 : 0));
  }
  const std::vector<scene::triangle>& tris = scene_->triangles();
  for (const edge_table::candidate& c : edges_.table->candidates) {
    bool silhouette = false;
    if (c.plane_a != no_triangle) {
      const std::int8_t fa = edges_.facing[c.plane_a], fb = edges_.facing[c.plane_b];
      if (fa != 0 && fa == fb) continue;
      silhouette = fa * fb < 0;
    }
    const scene::triangle& t = tris[c.triangle];
    const glm::vec3 a = basis.to_local(corner(t, c.k) - position);
    const glm::vec3 b = basis.to_local(corner(t, c.k == 2 ? 0 : c.k + 1) - position);
    if (a.z < 0.0f && b.z < 0.0f) continue;  // below the tangent plane: on no face
    ++stats_.edge_hard_edges;
    edge_mark_segment(a, b, silhouette);
  }
  stats_.edge_hard_texels = edges_.hard_texels.size();
}

// Marks the texels that the segment (a, b) (local frame) may cross on each face: the segment is
// clipped to the face's frustum widened by a texel (and to w >= near / 2), projected in double,
// and every texel within 1/16 texel of it is marked. The rasterizer's vertices differ from these
// by its float set-up and 1/512 texel of snapping, far below the margins, so no texel a hard edge
// crosses is missed; the margins only add a few texels of exact coverage.
void raster_detail::rasterizer_impl::edge_mark_segment(const glm::vec3& a, const glm::vec3& b, bool silhouette) {
  const int n = n_;
  const double grow = 1.0 + texel_step_, near = 0.5 * static_cast<double>(near_), eps = 1.0 / 16.0;
  for (int face = 0; face < 5; ++face) {
    const clip_vertex ca = to_clip(face, a), cb = to_clip(face, b);
    const glm::dvec3 pa(ca.u, ca.v, ca.w), pb(cb.u, cb.v, cb.w);
    // Liang-Barsky against g(p) >= 0 for each bounding plane g.
    double t0 = 0.0, t1 = 1.0;
    const auto keep = [&](double ga, double gb) {
      if (ga < 0.0 && gb < 0.0) return false;
      if (ga < 0.0) t0 = std::max(t0, ga / (ga - gb));
      else if (gb < 0.0) t1 = std::min(t1, ga / (ga - gb));
      return t0 <= t1;
    };
    const double v_low = face == 0 ? grow : texel_step_;  // side faces: v >= -1 texel
    if (!keep(pa.z - near, pb.z - near) || !keep(grow * pa.z - pa.x, grow * pb.z - pb.x) ||
        !keep(grow * pa.z + pa.x, grow * pb.z + pb.x) || !keep(grow * pa.z - pa.y, grow * pb.z - pb.y) ||
        !keep(v_low * pa.z + pa.y, v_low * pb.z + pb.y))
      continue;
    const glm::dvec3 q0 = pa + t0 * (pb - pa), q1 = pa + t1 * (pb - pa);
    // Texel coordinates (x, y in texels; centres at k + 1/2).
    const double half = 0.5 * n, v_offset = face == 0 ? 1.0 : 0.0;
    const double x0 = (q0.x / q0.z + 1.0) * half, y0 = (q0.y / q0.z + v_offset) * half;
    const double x1 = (q1.x / q1.z + 1.0) * half, y1 = (q1.y / q1.z + v_offset) * half;
    const int rows = face == 0 ? n : n / 2;
    const std::size_t face_offset = hemicube_face_offset(n, static_cast<hemicube_face>(face));
    const std::size_t row_base = face_row_base(n, face);
    const double ylo = std::min(y0, y1), yhi = std::max(y0, y1);
    const double inv_dy = yhi - ylo > 1e-12 ? 1.0 / (y1 - y0) : 0.0;  // (the margins dwarf its rounding)
    const int r_first = std::max(0, static_cast<int>(floor_int(ylo - eps)));
    const int r_last = std::min(rows - 1, static_cast<int>(floor_int(yhi + eps)));
    for (int r = r_first; r <= r_last; ++r) {
      // The segment's x range within the strip [r - eps, r + 1 + eps].
      double xlo = std::min(x0, x1), xhi = std::max(x0, x1);
      if (yhi - ylo > 1e-12) {
        const double s0 = std::max(0.0, std::min(1.0, (static_cast<double>(r) - eps - y0) * inv_dy));
        const double s1 = std::max(0.0, std::min(1.0, (static_cast<double>(r) + 1.0 + eps - y0) * inv_dy));
        const double xa = x0 + s0 * (x1 - x0), xb = x0 + s1 * (x1 - x0);
        xlo = std::min(xa, xb);
        xhi = std::max(xa, xb);
      }
      const int c_first = std::max(0, static_cast<int>(floor_int(xlo - eps)));
      const int c_last = std::min(n - 1, static_cast<int>(floor_int(xhi + eps)));
      if (c_first > c_last) continue;
      std::int32_t& lo = edges_.hard_rows[2 * (row_base + static_cast<std::size_t>(r))];
      std::int32_t& hi = edges_.hard_rows[2 * (row_base + static_cast<std::size_t>(r)) + 1];
      lo = std::min(lo, static_cast<std::int32_t>(c_first));
      hi = std::max(hi, static_cast<std::int32_t>(c_last));
      const std::size_t row = face_offset + static_cast<std::size_t>(r) * static_cast<std::size_t>(n);
      std::uint64_t* bits = edges_.hard_bits.data() + (row_base + static_cast<std::size_t>(r)) * edges_.words_per_row;
      std::uint64_t* outline = edges_.silhouette_bits.data() + (row_base + static_cast<std::size_t>(r)) * edges_.words_per_row;
      for (int c = c_first; c <= c_last; ++c) {
        std::uint64_t& word = bits[c >> 6];
        const std::uint64_t bit = std::uint64_t(1) << (c & 63);
        if (!(word & bit)) {
          word |= bit;
          edges_.hard_texels.push_back(static_cast<std::uint32_t>(row + static_cast<std::size_t>(c)));
        }
        if (silhouette) outline[c >> 6] |= bit;
      }
      edges_.hard_faces |= 1u << face;
    }
  }
}

// Whether a hard texel lies in columns c0..c1 of rows r0..r1 of `face` (the rows' hard column
// ranges, then the texels within them). Cost: O(rows + the texels within the rows' ranges).
bool raster_detail::rasterizer_impl::edge_box_is_hard(int face, std::int64_t c0, std::int64_t c1, std::int64_t r0,
                                           std::int64_t r1) const noexcept {
  const std::size_t row_base = face_row_base(n_, face);
  for (std::int64_t r = r0; r <= r1; ++r) {
    const std::size_t row = row_base + static_cast<std::size_t>(r);
    if (edges_.hard_rows[2 * row] > c1 || edges_.hard_rows[2 * row + 1] < c0) continue;
    bool any = false;
    edge_for_hard(row, std::max<std::int64_t>(c0, edges_.hard_rows[2 * row]), std::min<std::int64_t>(c1, edges_.hard_rows[2 * row + 1]),
                  [&](std::int64_t) { any = true; return false; });
    if (any) return true;
  }
  return false;
}

// Calls visit(c) for each hard column c in [c0, c1] of face row `row` (edges_.hard_bits), in order,
// until visit returns false.
template <class Visit>
void raster_detail::rasterizer_impl::edge_for_hard(std::size_t row, std::int64_t c0, std::int64_t c1, Visit&& visit) const {
  if (c0 > c1) return;
  const std::uint64_t* bits = edges_.hard_bits.data() + row * edges_.words_per_row;
  const std::int64_t w0 = c0 >> 6, w1 = c1 >> 6;
  for (std::int64_t w = w0; w <= w1; ++w) {
    const int lo = w == w0 ? static_cast<int>(c0 & 63) : 0, hi = w == w1 ? static_cast<int>(c1 & 63) : 63;
    std::uint64_t word = bits[w] & (~std::uint64_t(0) << lo) & (~std::uint64_t(0) >> (63 - hi));
    while (word) {
      if (!visit(w * 64 + lowest_bit(word))) return;
      word &= word - 1;
    }
  }
}

// The hard texels (edge_mark_hard) that the snapped triangle (px, py: fixed point, counter-
// clockwise) touches on `face`. A texel it covers whole makes it the texel's whole-texel
// candidate (edges_.whole_z, edges_.whole_id: the nearest, ties to the earlier draw); one it covers in part
// gets a fragment with the exact covered fraction of its weight and the triangle's unsnapped
// edges over the texel (edges_.fragment_shapes, for the blend's overlaps), unless a triangle drawn
// earlier covers the whole texel in front of it.
// Row by row over the box (the snapped box grown by the snapping, cut to the unsnapped
// triangle's): the rows' hard texels within it (edges_.hard_rows, edges_.hard_bits) are classified exactly
// with the integer edge functions at their corners (far: an edge leaves every corner more than
// 1/64 texel outside; whole: every corner of every edge >= 0; else partial). The rows' texels
// are not cut to the triangle's extent within each row: computing its crossings per row costs
// about what testing the row's few hard texels does (docs/design/raster.md). `exact`: the
// unsnapped vertices (x0, x1, x2, y0, y1, y2, fixed-point units), for the covered part. The
// coverage paths draw the triangle as without the option (centre samples). Cost: O(rows of the
// box + its hard texels), a partial texel ~100-200 instructions.
void raster_detail::rasterizer_impl::edge_texels(int face, const std::int64_t (&px)[3], const std::int64_t (&py)[3],
                                      const double (&exact)[6], const face_setup& fs, std::uint32_t draw,
                                      bool back) {
  const int n = n_;
  const int rows = face == 0 ? n : n / 2;
  const std::size_t face_offset = hemicube_face_offset(n, static_cast<hemicube_face>(face));
  const std::size_t row_base = face_row_base(n, face);
  std::int64_t dx[3], dy[3];
  for (int k = 0; k < 3; ++k) {
    const int b = k == 2 ? 0 : k + 1;
    dx[k] = px[b] - px[k];
    dy[k] = py[b] - py[k];
  }
  const std::int64_t min_y = std::min({py[0], py[1], py[2]}), max_y = std::max({py[0], py[1], py[2]});
  const std::int64_t min_x = std::min({px[0], px[1], px[2]}), max_x = std::max({px[0], px[1], px[2]});
  // Texels the box overlaps, grown by the snapping (half a unit) for the unsnapped triangle.
  // Cut to the texels the unsnapped triangle's box overlaps by a positive length (the others
  // share no area with it; a texel the snapped triangle covers whole is among them, the two
  // triangles' vertices being within half a unit of each other).
  const double ux_lo = std::min({exact[0], exact[1], exact[2]}), ux_hi = std::max({exact[0], exact[1], exact[2]});
  const double uy_lo = std::min({exact[3], exact[4], exact[5]}), uy_hi = std::max({exact[3], exact[4], exact[5]});
  const double inv_one = 1.0 / static_cast<double>(sub_one);  // (exact: a power of two)
  const std::int64_t uc_lo = floor_int(ux_lo * inv_one), uc_hi = ceil_int(ux_hi * inv_one) - 1;
  const std::int64_t ur_lo = floor_int(uy_lo * inv_one), ur_hi = ceil_int(uy_hi * inv_one) - 1;
  const std::int64_t col_lo = std::max<std::int64_t>({floor_sub(min_x - 1), uc_lo, 0});
  const std::int64_t col_hi = std::min<std::int64_t>({ceil_sub(max_x + 1) - 1, uc_hi, n - 1});
  const std::int64_t row_lo = std::max<std::int64_t>({floor_sub(min_y - 1), ur_lo, 0});
  const std::int64_t row_hi = std::min<std::int64_t>({ceil_sub(max_y + 1) - 1, ur_hi, rows - 1});
  if (col_lo > col_hi || row_lo > row_hi) return;
  // The unsnapped triangle's values, made at its first partial texel (many calls have none: all
  // their hard texels are far, whole, behind or in a silhouette's back sheet).
  //  - The unsnapped edge functions f_k(x, y) = edx (y - ay) - edy (x - ax) (fixed point, vertex
  //    k = (ax, ay)), their steps across a texel (gx, gy) and the extremes of those over the texel;
  //  - the edges for texel_part_inside (texel units; their reciprocals when they first cut a
  //    texel: have_reciprocals);
  //  - positive: only a counter-clockwise unsnapped triangle has an inside (snapping, by at most
  //    half a unit, can turn a sliver around): another gets no partial texels;
  //  - tiny: a triangle within one texel (the terrain's far triangles): its covered weight is its
  //    area times the density at its centroid, exact for a density linear over the texel, with
  //    no clipping (what clipping the square by its three edges gives, to rounding).
  double edx[3], edy[3], gx[3], gy[3], gx_lo[3], gx_hi[3], edge_norm[3];
  clip_edge ce[3];
  unsigned have_reciprocals = 0;
  bool unsnapped_ready = false, positive = false;
  const bool tiny = uc_lo == uc_hi && ur_lo == ur_hi;
  double tiny_area = 0.0, tiny_x = 0.0, tiny_y = 0.0;  // texel units; centroid about the texel's centre
  const auto make_unsnapped = [&] {
    for (int k = 0; k < 3; ++k) {
      const int b = k == 2 ? 0 : k + 1;
      edx[k] = exact[b] - exact[k];
      edy[k] = exact[3 + b] - exact[3 + k];
      gx[k] = -edy[k] * static_cast<double>(sub_one);
      gy[k] = edx[k] * static_cast<double>(sub_one);
      gx_lo[k] = std::min(gx[k], 0.0) + std::min(gy[k], 0.0);
      gx_hi[k] = std::max(gx[k], 0.0) + std::max(gy[k], 0.0);
      edge_norm[k] = std::sqrt(gx[k] * gx[k] + gy[k] * gy[k]);
      ce[k].ax = exact[k] * inv_one;
      ce[k].ay = exact[3 + k] * inv_one;
      ce[k].dx = edx[k] * inv_one;
      ce[k].dy = edy[k] * inv_one;
      ce[k].gx = gx[k];
      ce[k].gy = gy[k];
    }
    positive = edx[0] * edy[2] - edx[2] * edy[0] < 0.0;
    if (tiny) {
      const double ax = exact[1] - exact[0], ay = exact[4] - exact[3], bx = exact[2] - exact[0], by = exact[5] - exact[3];
      tiny_area = 0.5 * (ax * by - bx * ay) * (inv_one * inv_one);
      tiny_x = (exact[0] + exact[1] + exact[2]) * (inv_one / 3.0) - static_cast<double>(uc_lo) - 0.5;
      tiny_y = (exact[3] + exact[4] + exact[5]) * (inv_one / 3.0) - static_cast<double>(ur_lo) - 0.5;
    }
    unsnapped_ready = true;
  };
  // Whole: every corner of the texel inside the snapped triangle (exact integers). Far: every
  // corner more than 4 units (1/64 texel) outside an edge of it; the unsnapped triangle's edges
  // are within ~2 units of the snapped ones over its box, so it has no area there. With the
  // edge function e_k at the texel's lower left corner, the texel is whole when e_k >=
  // whole_at[k] for every edge and far when e_k < far_below[k] for some edge; e_k steps by
  // step_x[k] per column (exact integers: terms below 2^61, see guard_band).
  std::int64_t step_x[3], whole_at[3], far_below[3];
  for (int k = 0; k < 3; ++k) {
    const std::int64_t sx = -dy[k] * sub_one, sy = dx[k] * sub_one;
    step_x[k] = sx;
    whole_at[k] = -(std::min<std::int64_t>(sx, 0) + std::min<std::int64_t>(sy, 0));
    far_below[k] = -4 * (std::abs(dx[k]) + std::abs(dy[k])) - (std::max<std::int64_t>(sx, 0) + std::max<std::int64_t>(sy, 0));
  }
  // Per row: the edge functions at its column 0 (snapped: made at the first row with hard
  // texels, then stepped row by row, exactly; unsnapped: made at the row's first partial texel)
  // and the depth row.
  std::int64_t e_row[3] = {0, 0, 0};
  std::int64_t e_row_at = -1, f_row_at = -1;  // the rows they hold
  double f_row[3];
  float zrow = 0.0f;
  // The statistics, counted here and added at the end (an increment of the member per texel
  // would chain every iteration through memory).
  std::size_t tested = 0, kept = 0;
  const auto classify = [&](std::int64_t c, std::int64_t r, std::size_t texel) {
    ++tested;
    const std::int64_t e0 = e_row[0] + c * step_x[0], e1 = e_row[1] + c * step_x[1], e2 = e_row[2] + c * step_x[2];
    if ((e0 < far_below[0]) | (e1 < far_below[1]) | (e2 < far_below[2])) return;
    const bool whole = (e0 >= whole_at[0]) & (e1 >= whole_at[1]) & (e2 >= whole_at[2]);
    // The triangle's depth at the texel centre, as the coverage paths compute it.
    float z = zrow + fs.dzdx * static_cast<float>(c);
    z = z > FLT_MIN ? z : FLT_MIN;
    if (whole) {
      if (z > edges_.whole_z[texel]) {
        edges_.whole_z[texel] = z;
        edges_.whole_id[texel] = draw;
      }
      return;
    }
    if (!unsnapped_ready) make_unsnapped();
    if (!positive) return;
    // Behind a triangle drawn earlier that covers the whole texel: it can take no share (the
    // blend stops at the whole-texel winner, which can only come nearer).
    if (!(z > edges_.whole_z[texel])) return;
    // Facing away, in a texel a silhouette crosses: near a silhouette the surface's far sheet
    // lies behind its near one over the same part of the texel (a ray entering the surface
    // leaves it through the far sheet), which the blend, taking fragments as side by side,
    // would count again in place of what lies behind.
    if (back && (edges_.silhouette_bits[(row_base + static_cast<std::size_t>(r)) * edges_.words_per_row + static_cast<std::size_t>(c >> 6)] >> (c & 63) & 1u)) return;
    // The covered part is measured against the unsnapped edges (f0 + gx x + gy y >= 0 over the
    // texel, x, y in [0, 1]), so slivers a fraction of a texel wide keep their width; the
    // snapped edges decide which texels are whole. The two differ by less than 1/512 texel. Two
    // triangles sharing an edge clip it from the same unsnapped endpoints, so between them they
    // miss no part of a texel.
    //
    // The integrator weights a texel by the projected solid angle over it; within the texel its
    // density is taken linear about the centre, 1 + wx (x - 1/2) + wy (y - 1/2) (relative to the
    // centre's, in texel units; edges_.density): the covered fraction of the texel's weight, to
    // second order.
    const float* slope = edges_.density.data() + 2 * texel;
    const double wx = slope[0], wy = slope[1];
    if (f_row_at != r) {
      const double y0 = static_cast<double>(r * sub_one);
      for (int k = 0; k < 3; ++k) f_row[k] = edx[k] * (y0 - exact[3 + k]) + edy[k] * exact[k];
      f_row_at = r;
    }
    fragment_shape shape;  // the unsnapped edges over this texel (for the blend's overlaps)
    unsigned clip = 0;     // the unsnapped edges that cut the texel
    for (int k = 0; k < 3; ++k) {
      shape.f0[k] = f_row[k] + static_cast<double>(c) * gx[k];
      shape.gx[k] = gx[k];
      shape.gy[k] = gy[k];
      shape.norm[k] = edge_norm[k];
      if (shape.f0[k] + gx_hi[k] <= 0.0) return;  // no area in common
      if (shape.f0[k] + gx_lo[k] < 0.0) clip |= 1u << k;
    }
    double area;
    if (tiny) {
      area = tiny_area * (1.0 + wx * tiny_x + wy * tiny_y);
    } else {
      if ((clip & ~have_reciprocals) != 0) {
        for (int k = 0; k < 3; ++k)
          if ((clip & ~have_reciprocals) >> k & 1u) {
            ce[k].rdx = 1.0 / ce[k].dx;
            ce[k].rdy = 1.0 / ce[k].dy;
            ce[k].rgx = 1.0 / ce[k].gx;
            ce[k].rgy = 1.0 / ce[k].gy;
          }
        have_reciprocals |= clip;
      }
      if (clip == 0)
        area = 1.0;
      else if ((clip & (clip - 1)) == 0) {  // one cutting edge (most partial texels): the corners' form
        const int k = clip == 1 ? 0 : (clip == 2 ? 1 : 2);
        area = square_part_inside_one(shape.f0[k], ce[k].gx, ce[k].gy, ce[k].rgx, ce[k].rgy, wx, wy);
      } else {
        area = texel_part_inside(ce, shape.f0, clip, static_cast<double>(c) + 0.5, static_cast<double>(r) + 0.5, wx, wy);
      }
    }
    if (!(area > 0.0)) return;
    shape.clip = clip;
    edge_fragment fr;
    fr.texel = static_cast<std::uint32_t>(texel);
    fr.z = z;
    fr.coverage = static_cast<float>(std::min(area, 1.0));
    fr.id = draw;
    fr.mask = 0;  // (made by the blend when first needed)
    fr.shape = static_cast<std::uint32_t>(edges_.fragment_shapes.size());
    edges_.fragment_shapes.push_back(shape);
    if (edges_.fragment_count[texel]++ == 0) edges_.fragment_texels.push_back(fr.texel);
    edges_.fragments.push_back(fr);
    ++kept;
  };

  for (std::int64_t r = row_lo; r <= row_hi; ++r) {
    const std::int32_t hard_lo = edges_.hard_rows[2 * (row_base + static_cast<std::size_t>(r))];
    const std::int32_t hard_hi = edges_.hard_rows[2 * (row_base + static_cast<std::size_t>(r)) + 1];
    if (hard_lo > col_hi || hard_hi < col_lo) continue;
    const std::int64_t c0 = std::max<std::int64_t>(col_lo, hard_lo), c1 = std::min<std::int64_t>(col_hi, hard_hi);
    const std::size_t row = face_offset + static_cast<std::size_t>(r) * static_cast<std::size_t>(n);
    if (r != e_row_at) {
      const std::int64_t y0 = r * sub_one;
      for (int k = 0; k < 3; ++k) e_row[k] = dx[k] * (y0 - py[k]) + dy[k] * px[k];
    }
    e_row_at = r + 1;  // the next row's values follow by a step
    f_row_at = -1;
    zrow = static_cast<float>(fs.z00 + fs.dzdy * static_cast<double>(r));
    edge_for_hard(row_base + static_cast<std::size_t>(r), c0, c1, [&](std::int64_t c) {
      classify(c, r, row + static_cast<std::size_t>(c));
      return true;
    });
    for (int k = 0; k < 3; ++k) e_row[k] += dx[k] * sub_one;
  }
  stats_.edge_texels_tested += tested;
  stats_.edge_fragments += kept;
}

// After the resolve (which gave every texel its centre sample, as without the option): each
// hard texel with fragments gets its fragments made contiguous, in the order they were added (a
// counting sort by texel; the texels in first-touch order). edges_.fragment_count becomes each
// texel's end.
void raster_detail::rasterizer_impl::edge_group_fragments() {
  edges_.groups.reserve(edges_.fragment_texels.size());
  std::uint32_t offset = 0;
  for (const std::uint32_t t : edges_.fragment_texels) {
    edges_.groups.push_back({t, offset, edges_.fragment_count[t]});
    edges_.fragment_count[t] = offset;
    offset += edges_.groups.back().count;
  }
  edges_.grouped.resize(edges_.fragments.size());
  for (const edge_fragment& fr : edges_.fragments) edges_.grouped[edges_.fragment_count[fr.texel]++] = fr;
}

// The radiance a draw (texel id) gives at a texel whose centre direction meets its plane at 1/w
// = z: the resolve's computation (shade, or the texture at the perspective-correct UV).
glm::vec3 raster_detail::rasterizer_impl::fragment_radiance(std::uint32_t id, std::size_t texel, float z,
                                                 const radiance_texture* texture) const {
  const std::uint32_t draw = id >> key_bits_;
  if (textured_ && draws_[draw].textured) return textured_texel(draws_[draw], texel, lengths_[texel] / z, *texture);
  const shade& sh = shades_[key_bits_ ? id & ((1u << key_bits_) - 1u) : draw_keys_[id]];
  return {sh.r, sh.g, sh.b};
}

// The fragments of a texel, front to back, whose overlaps with those before them the blend
// measures (edge_hidden_part): the pairs' work is at most edge_overlap_limit^2 / 2 per texel.
constexpr std::uint32_t edge_overlap_limit = 16;

// For the blend of one texel: the part of fragment i of order (its covered fraction of the
// texel's weight) that the fragments before it (front to back) cover. For each of them that may
// overlap it (not a part of the same draw, no edge shared from opposite sides
// (edge_shared_opposite), a common cell of the texel's 8 x 8 grid (edge_cell_mask, made here when
// first needed)) the part inside both (overlap_part) is added. Exact when those earlier fragments do not overlap each other over it (up to double
// rounding); where three or more overlap at once a part may be counted twice (the share is then
// clamped at 0 by the caller). Fragments side by side (triangles sharing an edge, most texels)
// give 0: the blend is as without this step. Cost: i pair tests, one polygon clip per
// overlapping pair.
double raster_detail::rasterizer_impl::edge_hidden_part(edge_fragment* order, std::uint32_t i, double wx,
                                                        double wy) const {
  double hidden = 0.0;
  edge_fragment& b = order[i];
  const fragment_shape& sb = edges_.fragment_shapes[b.shape];
  for (std::uint32_t j = 0; j < i; ++j) {
    edge_fragment& a = order[j];
    // Two parts of one clipped triangle (its fan), or neighbours across an edge: no overlap.
    if (a.id == b.id) continue;
    const fragment_shape& sa = edges_.fragment_shapes[a.shape];
    if (edge_shared_opposite(sa, sb)) continue;
    // No common cell: no overlap. (The cells are made when first needed; 0 = not yet.)
    if (a.mask == 0) a.mask = edge_cell_mask(sa.f0, sa.gx, sa.gy, sa.clip);
    if (b.mask == 0) b.mask = edge_cell_mask(sb.f0, sb.gx, sb.gy, sb.clip);
    if ((a.mask & b.mask) == 0) continue;
    const double part = overlap_part(sa, sb, wx, wy);
    if (part > 0.0) hidden += part;
  }
  return hidden;
}

// After the resolve: each texel with fragments gets the blend of what covers it. Its fragments,
// front to back (1/w at the texel centre, larger first; ties: the earlier draw first, then the
// order they were added), each take min(its own part, what is left) until the whole-texel
// winner (or the first fragment behind it), which takes the rest; with no whole-texel winner the
// sky takes the rest. A fragment's own part is its coverage less what the fragments before it
// cover of it (edge_hidden_part). Deterministic: the order is total and the sums run in it.
void raster_detail::rasterizer_impl::edge_blend(hemicube_buffer& out, const frame& basis, const radiance_texture* texture) {
  const auto draw_of = [this](std::uint32_t id) { return id >> key_bits_; };
  // A draw's radiance: its shade (inline; most renders have no texture), else fragment_radiance.
  const auto radiance = [&](std::uint32_t id, std::size_t texel, float z) {
    if (textured_) return fragment_radiance(id, texel, z, texture);
    const shade& sh = shades_[key_bits_ ? id & ((1u << key_bits_) - 1u) : draw_keys_[id]];
    return glm::vec3(sh.r, sh.g, sh.b);
  };
  float* red = out.channel(0);
  float* green = out.channel(1);
  float* blue = out.channel(2);
  for (const edge_group& g : edges_.groups) {
    const float full_z = edges_.whole_z[g.texel];  // the nearest triangle covering the whole texel (0 = none)
    const std::uint32_t full_id = edges_.whole_id[g.texel];
    // The group is in the order the fragments were added; a stable insertion sort by
    // (z descending, draw ascending) keeps that order for ties.
    edge_fragment* order = edges_.grouped.data() + g.first;
    for (std::uint32_t i = 1; i < g.count; ++i) {
      const edge_fragment f = order[i];
      std::uint32_t j = i;
      const auto before = [&](const edge_fragment& fa, const edge_fragment& fb) {
        return fa.z > fb.z || (fa.z == fb.z && draw_of(fa.id) < draw_of(fb.id));
      };
      while (j > 0 && before(f, order[j - 1])) {
        order[j] = order[j - 1];
        --j;
      }
      order[j] = f;
    }
    glm::vec3 sum(0.0f);
    const float* slope = edges_.density.data() + 2 * g.texel;
    const double wx = slope[0], wy = slope[1];

    float left = 1.0f, nearest = 0.0f;  // nearest: 1/w of the first fragment with a share
    for (std::uint32_t i = 0; i < g.count; ++i) {
      const edge_fragment& fr = order[i];
      if (full_z > 0.0f && (fr.z < full_z || (fr.z == full_z && draw_of(fr.id) > draw_of(full_id)))) break;
      // Its coverage less what nearer partial triangles cover of it (all of it for fragments
      // side by side: the same bits as without this step).
      // (Past the first edge_overlap_limit fragments of a texel, as at the horizon of a terrain
      // at small N with hundreds of tiny triangles in a texel, the rest are taken side by side:
      // the pairs' cost would grow as their square.)
      const double hidden = i < edge_overlap_limit ? edge_hidden_part(order, i, wx, wy) : 0.0;
      const float own = hidden > 0.0 ? static_cast<float>(std::max(0.0, static_cast<double>(fr.coverage) - hidden)) : fr.coverage;
      const float share = std::min(own, left);
      if (share > 0.0f && nearest == 0.0f) nearest = fr.z;
      sum += share * radiance(fr.id, g.texel, fr.z);
      left -= share;
      if (!(left > 0.0f)) break;
    }
    // The texel's distance: along the centre's direction to the plane of the nearest triangle
    // with a share of it (not necessarily the one the centre sees; the flags stay the centre's).
    // The translation gradient's walls move with the nearer texel's distance: a blended texel
    // at an occluding edge must carry the occluder's distance, or half the edge's radiance step
    // would move with the surface behind; and one whose centre sees nothing must not be at +inf
    // (a wall between two texels at +inf contributes nothing).
    if (nearest > 0.0f) {
      const float distance = lengths_[g.texel] / nearest;
      if (distance < out.distance[g.texel]) out.distance[g.texel] = distance;
    }
    if (left > 0.0f) {
      glm::vec3 rest;
      if (full_z > 0.0f)
        rest = radiance(full_id, g.texel, full_z);
      else if (sky_)
        rest = glm::vec3(sky_->sample(basis.to_world(directions_[g.texel])));
      else
        rest = glm::vec3(shades_[0].r, shades_[0].g, shades_[0].b);
      sum += left * rest;
    }
    red[g.texel] = sum.x;
    green[g.texel] = sum.y;
    blue[g.texel] = sum.z;
  }
}

}  // namespace hemilight
