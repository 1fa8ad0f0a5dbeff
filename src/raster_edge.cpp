// Exact edge coverage (raster_options::edge_coverage; docs/raster.md, "Exact edge coverage"): the
// partial texels of each drawn triangle, their front-to-back resolve and blend.
#include "hemilight/raster.hpp"
#include "raster_internal.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>

namespace hemilight {

using namespace raster_detail;

// ---------------------------------------------------------------------------------------------
// Exact edge coverage (raster_options::edge_coverage; docs/raster.md, "Exact edge coverage")
// ---------------------------------------------------------------------------------------------

namespace {

// The part of the unit square [0, 1]^2 (a texel, in texel units) inside the half-planes
// f_k(x, y) = f0[k] + gx[k] x + gy[k] y >= 0 of the edges in `clip` (bit k): Sutherland-Hodgman
// on the square's polygon (at most 4 + 3 vertices), then the polygon's area and first moments
// about the square's centre (the shoelace formula and its moment form), weighted by the density
// 1 + wx (x - 1/2) + wy (y - 1/2). Double precision: within ~1e-15 of the exact value for the
// snapped triangle. The square's own moments vanish, so the values of two triangles sharing an
// edge sum to those of their union.
double square_part_inside(const double (&f0)[3], const double (&gx)[3], const double (&gy)[3], unsigned clip,
                          double wx, double wy) noexcept {
  double px[8] = {0.0, 1.0, 1.0, 0.0}, py[8] = {0.0, 0.0, 1.0, 1.0};
  double qx[8], qy[8];
  int count = 4;
  for (int k = 0; k < 3 && count >= 3; ++k) {
    if (!(clip >> k & 1u)) continue;
    double value[8];
    for (int i = 0; i < count; ++i) value[i] = f0[k] + gx[k] * px[i] + gy[k] * py[i];
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
        const double t = value[i] / (value[i] - value[j]);
        qx[out] = px[i] + t * (px[j] - px[i]);
        qy[out] = py[i] + t * (py[j] - py[i]);
        ++out;
      }
    }
    count = out;
    std::copy(qx, qx + out, px);
    std::copy(qy, qy + out, py);
  }
  if (count < 3) return 0.0;
  double twice = 0.0, mx = 0.0, my = 0.0;  // 2 area, 6 first moments (about the centre)
  for (int i = 0; i < count; ++i) {
    const int j = i + 1 == count ? 0 : i + 1;
    const double ax = px[i] - 0.5, ay = py[i] - 0.5, bx = px[j] - 0.5, by = py[j] - 0.5;
    const double cross = ax * by - bx * ay;
    twice += cross;
    mx += (ax + bx) * cross;
    my += (ay + by) * cross;
  }
  return 0.5 * twice + (wx * mx + wy * my) / 6.0;
}

}  // namespace

// The texels that the snapped triangle (px, py: fixed point, counter-clockwise) covers in part on
// `face`: each gets a fragment with the exact covered fraction of its area. Row by row: the
// triangle's x extent within the row's strip (its vertices in the strip and its edges' crossings
// of the strip's lines) bounds the texels it touches; they are classified exactly with the
// integer edge functions at their corners (outside: an edge leaves every corner at <= 0, i.e. no
// area in common; whole: every corner of every edge >= 0; else partial), from both ends of the
// row inwards until a whole texel (the triangle is convex: its whole texels in a row are
// contiguous, with the partial ones on either side). Whole texels are left to the coverage
// paths. `exact`: the unsnapped vertices (x0, x1, x2, y0, y1, y2, fixed-point units), for the
// covered part. Cost: O(rows + partial texels).
void hemicube_rasterizer::edge_texels(int face, const std::int64_t (&px)[3], const std::int64_t (&py)[3],
                                      const double (&exact)[6], const face_setup& fs, std::uint32_t draw) {
  const int n = n_;
  const int rows = face == 0 ? n : n / 2;
  const std::size_t face_offset = hemicube_face_offset(n, static_cast<hemicube_face>(face));
  std::int64_t dx[3], dy[3], tie[3];
  for (int k = 0; k < 3; ++k) {
    const int b = k == 2 ? 0 : k + 1;
    dx[k] = px[b] - px[k];
    dy[k] = py[b] - py[k];
    tie[k] = dy[k] > 0 || (dy[k] == 0 && dx[k] < 0) ? 0 : 1;  // the coverage paths' tie bias
  }
  const std::int64_t min_y = std::min({py[0], py[1], py[2]}), max_y = std::max({py[0], py[1], py[2]});
  const std::int64_t min_x = std::min({px[0], px[1], px[2]}), max_x = std::max({px[0], px[1], px[2]});
  // Texels the box overlaps, grown by the snapping (half a unit) for the unsnapped triangle.
  const std::int64_t col_lo = std::max<std::int64_t>(floor_sub(min_x - 1), 0);
  const std::int64_t col_hi = std::min<std::int64_t>(ceil_sub(max_x + 1) - 1, n - 1);
  const std::int64_t row_lo = std::max<std::int64_t>(floor_sub(min_y - 1), 0);
  const std::int64_t row_hi = std::min<std::int64_t>(ceil_sub(max_y + 1) - 1, rows - 1);

  // The unsnapped edge functions f_k(x, y) = edx (y - ay) - edy (x - ax) (fixed point, vertex k
  // = (ax, ay)), their steps across a texel (gx, gy) and the extremes of those over the texel.
  double edx[3], edy[3], gx[3], gy[3], gx_lo[3], gx_hi[3];
  for (int k = 0; k < 3; ++k) {
    const int b = k == 2 ? 0 : k + 1;
    edx[k] = exact[b] - exact[k];
    edy[k] = exact[3 + b] - exact[3 + k];
    gx[k] = -edy[k] * static_cast<double>(sub_one);
    gy[k] = edx[k] * static_cast<double>(sub_one);
    gx_lo[k] = std::min(gx[k], 0.0) + std::min(gy[k], 0.0);
    gx_hi[k] = std::max(gx[k], 0.0) + std::max(gy[k], 0.0);
  }
  // 0: no area in common, 1: partial (a fragment is added), 2: the whole texel.
  const auto classify = [&](std::int64_t c, std::int64_t r) -> int {
    ++stats_.edge_texels_tested;
    const std::int64_t x0 = c * sub_one, y0 = r * sub_one;
    // The covered part is measured against the unsnapped edges (f0 + gx x + gy y >= 0 over the
    // texel, x, y in [0, 1]), so slivers a fraction of a texel wide keep their width; the
    // snapped edges (exact integers) decide which texels the coverage paths draw whole and
    // which centres are covered (as without the option). The two differ by less than 1/512
    // texel. Two triangles sharing an edge clip it from the same unsnapped endpoints, so
    // between them they miss no part of a texel.
    double f0[3];
    bool outside = false;
    unsigned clip = 0;  // the unsnapped edges that cut the texel
    for (int k = 0; k < 3; ++k) {
      f0[k] = edx[k] * (static_cast<double>(y0) - exact[3 + k]) - edy[k] * (static_cast<double>(x0) - exact[k]);
      outside = outside || f0[k] + gx_hi[k] <= 0.0;
      if (f0[k] + gx_lo[k] < 0.0) clip |= 1u << k;
    }
    // The snapped edge functions at the texel's (x0, y0) corner and their steps across it.
    bool whole = true, centre = true;
    for (int k = 0; k < 3; ++k) {
      const std::int64_t e = dx[k] * (y0 - py[k]) - dy[k] * (x0 - px[k]);
      const std::int64_t sx = -dy[k] * sub_one, sy = dx[k] * sub_one;
      whole = whole && e + std::min<std::int64_t>(sx, 0) + std::min<std::int64_t>(sy, 0) >= 0;
      centre = centre && e + (sx + sy) / 2 - tie[k] >= 0;  // exact: sx, sy are multiples of 256
    }
    if (whole) return 2;
    if (outside && !centre) return 0;

    // The integrator weights a texel by the projected solid angle over it; within the texel its
    // density is taken linear about the centre, 1 + wx (x - 1/2) + wy (y - 1/2) (relative to the
    // centre's, in texel units): the covered fraction of the texel's weight, to second order.
    // Top face (z = 1): density (1 + u^2 + v^2)^-2; side faces (v = height): v (1 + u^2 + v^2)^-2.
    const double u = first_centre_ + texel_step_ * static_cast<double>(c);
    const double v = (face == 0 ? first_centre_ : 0.5 * texel_step_) + texel_step_ * static_cast<double>(r);
    const double q = 1.0 + u * u + v * v;
    const double wx = -4.0 * u / q * texel_step_;
    const double wy = (face == 0 ? -4.0 * v / q : 1.0 / v - 4.0 * v / q) * texel_step_;
    const double area = outside ? 0.0 : square_part_inside(f0, gx, gy, clip, wx, wy);
    // (A covered centre always makes a fragment, for the centre's resolve, even of no area.)
    if (!(area > 0.0) && !centre) return 0;
    edge_fragment fr;
    fr.texel = static_cast<std::uint32_t>(face_offset + static_cast<std::size_t>(r) * static_cast<std::size_t>(n) +
                                          static_cast<std::size_t>(c));
    // The coverage paths' depth at this texel, bit for bit (span: the row in double, then float).
    const auto zrow = static_cast<float>(fs.z00 + fs.dzdy * static_cast<double>(r));
    const float z = zrow + fs.dzdx * static_cast<float>(c);
    fr.z = z > FLT_MIN ? z : FLT_MIN;
    fr.coverage = static_cast<float>(std::min(std::max(area, 0.0), 1.0));
    fr.id = draw;
    fr.centre = centre;
    std::uint32_t& head = fragment_head_[fr.texel];
    if (head == no_triangle) fragment_texels_.push_back(fr.texel);
    fr.next = head;
    head = static_cast<std::uint32_t>(fragments_.size());
    fragments_.push_back(fr);
    ++stats_.edge_fragments;
    return 1;
  };

  for (std::int64_t r = row_lo; r <= row_hi; ++r) {
    // The triangle's x extent within the strip y0 <= y <= y1 (fixed point, in double).
    const std::int64_t y0 = r * sub_one, y1 = y0 + sub_one;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int k = 0; k < 3; ++k) {
      if (py[k] >= y0 && py[k] <= y1) {
        lo = std::min(lo, static_cast<double>(px[k]));
        hi = std::max(hi, static_cast<double>(px[k]));
      }
      const int b = k == 2 ? 0 : k + 1;
      for (const std::int64_t y : {y0, y1}) {
        if ((py[k] < y) == (py[b] < y)) continue;
        const double x = static_cast<double>(px[k]) +
                         static_cast<double>(y - py[k]) / static_cast<double>(dy[k]) * static_cast<double>(dx[k]);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
    }
    if (!(lo <= hi)) continue;
    // Widened by a texel each way (the crossings are rounded; the classification is exact).
    const std::int64_t c0 = std::max(col_lo, static_cast<std::int64_t>(std::floor(lo / sub_one)) - 1);
    const std::int64_t c1 = std::min(col_hi, static_cast<std::int64_t>(std::floor(hi / sub_one)) + 1);
    std::int64_t c = c0;
    for (; c <= c1; ++c)
      if (classify(c, r) == 2) break;
    if (c > c1) continue;  // no whole texel in the row: every texel was classified
    for (std::int64_t d = c1; d > c; --d)
      if (classify(d, r) == 2) break;
  }
}

// Before the resolve: the texels with fragments get what the texel centre sees, as a render
// without edge coverage would (the depth buffer holds the nearest triangle covering the whole
// texel; a fragment covering the centre and nearer, or as near and drawn earlier, wins), so
// distance, flags and seen_triangle() keep their meaning bit for bit. The whole-texel winner is
// kept for the blend.
void hemicube_rasterizer::edge_resolve_centres() {
  const auto draw_of = [this](std::uint32_t id) { return id >> key_bits_; };
  edge_groups_.reserve(fragment_texels_.size());
  for (const std::uint32_t t : fragment_texels_) {
    const float full_z = depth_[t];
    const std::uint32_t full_id = full_z > 0.0f ? ids_[t] : 0u;
    edge_groups_.push_back({t, full_z, full_id, 0.0f});
    float best_z = full_z;
    std::uint32_t best_id = full_id;
    for (std::uint32_t f = fragment_head_[t]; f != no_triangle; f = fragments_[f].next) {
      const edge_fragment& fr = fragments_[f];
      if (!fr.centre) continue;
      if (best_z == 0.0f || fr.z > best_z || (fr.z == best_z && draw_of(fr.id) < draw_of(best_id))) {
        best_z = fr.z;
        best_id = fr.id;
      }
    }
    depth_[t] = best_z;
    ids_[t] = best_id;
    edge_groups_.back().centre_z = best_z;
  }
}

// The radiance a draw (texel id) gives at a texel whose centre direction meets its plane at 1/w
// = z: the resolve's computation (shade, or the texture at the perspective-correct UV).
glm::vec3 hemicube_rasterizer::fragment_radiance(std::uint32_t id, std::size_t texel, float z,
                                                 const radiance_texture* texture) const {
  const std::uint32_t draw = id >> key_bits_;
  if (textured_ && draws_[draw].textured) {
    const draw_record& rec = draws_[draw];
    const float distance = lengths_[texel] / z;
    const glm::vec3 q = distance * directions_[texel] - rec.v0;
    const float b1 = glm::dot(rec.grad_b1, q), b2 = glm::dot(rec.grad_b2, q);
    const std::vector<glm::vec2>& uvs = scene_->lightmap_uvs();
    const std::vector<std::uint32_t>& indices = scene_->indices();
    const std::size_t tri = 3 * static_cast<std::size_t>(rec.index);
    const glm::vec2& uv0 = uvs[indices[tri]];
    const glm::vec2 uv = uv0 + b1 * (uvs[indices[tri + 1]] - uv0) + b2 * (uvs[indices[tri + 2]] - uv0);
    return texture->sample(uv);
  }
  const shade& sh = shades_[key_bits_ ? id & ((1u << key_bits_) - 1u) : draw_keys_[id]];
  return {sh.r, sh.g, sh.b};
}

// After the resolve: each texel with fragments gets the blend of what covers it. Its fragments,
// front to back (1/w at the texel centre, larger first; ties: the earlier draw first, then the
// order they were added), each take min(coverage, what is left) until the whole-texel winner
// (or the first fragment behind it), which takes the rest; with no whole-texel winner the sky
// takes the rest. Deterministic: the order is total and the sums run in it.
void hemicube_rasterizer::edge_blend(hemicube_buffer& out, const frame& basis, const radiance_texture* texture) {
  const auto draw_of = [this](std::uint32_t id) { return id >> key_bits_; };
  std::vector<std::uint32_t> order;
  float* red = out.channel(0);
  float* green = out.channel(1);
  float* blue = out.channel(2);
  for (const edge_group& g : edge_groups_) {
    order.clear();
    for (std::uint32_t f = fragment_head_[g.texel]; f != no_triangle; f = fragments_[f].next) order.push_back(f);
    // The list runs newest first: reversed, it is in the order the fragments were added; a stable
    // insertion sort by (z descending, draw ascending) then keeps that order for ties.
    std::reverse(order.begin(), order.end());
    for (std::size_t i = 1; i < order.size(); ++i) {
      const std::uint32_t f = order[i];
      std::size_t j = i;
      const auto before = [&](std::uint32_t a, std::uint32_t b) {
        const edge_fragment &fa = fragments_[a], &fb = fragments_[b];
        return fa.z > fb.z || (fa.z == fb.z && draw_of(fa.id) < draw_of(fb.id));
      };
      while (j > 0 && before(f, order[j - 1])) {
        order[j] = order[j - 1];
        --j;
      }
      order[j] = f;
    }
    glm::vec3 sum(0.0f);
    float left = 1.0f, nearest = 0.0f;  // nearest: 1/w of the first fragment with a share
    for (const std::uint32_t f : order) {
      const edge_fragment& fr = fragments_[f];
      if (g.full_z > 0.0f && (fr.z < g.full_z || (fr.z == g.full_z && draw_of(fr.id) > draw_of(g.full_id)))) break;
      const float share = std::min(fr.coverage, left);
      if (share > 0.0f && nearest == 0.0f) nearest = fr.z;
      sum += share * fragment_radiance(fr.id, g.texel, fr.z, texture);
      left -= share;
      if (!(left > 0.0f)) break;
    }
    // The texel's distance: along the centre's direction to the plane of the nearest triangle
    // with a share of it (not necessarily the one the centre sees; the flags stay the centre's).
    // The translation gradient's walls move with the nearer texel's distance: a blended texel
    // at an occluding edge must carry the occluder's distance, or half the edge's radiance step
    // would move with the surface behind; and one whose centre sees nothing must not be at +inf
    // (a wall between two texels at +inf contributes nothing).
    if (nearest > 0.0f && nearest > g.centre_z) out.distance[g.texel] = lengths_[g.texel] / nearest;
    if (left > 0.0f) {
      glm::vec3 rest;
      if (g.full_z > 0.0f)
        rest = fragment_radiance(g.full_id, g.texel, g.full_z, texture);
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
