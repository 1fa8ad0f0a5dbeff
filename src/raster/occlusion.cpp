// Occlusion culling of the hemicube rasterizer (raster_options::diagnostics.occlusion_culling;
// docs/raster.md, "Occlusion culling"): the conservative hierarchical depth and the test of a BVH
// node against it. Members of raster_detail::rasterizer_impl (internal.hpp).
//
// Depths are 1/w (larger = nearer, 0 = nothing drawn). A tile of 8 x 8 texels keeps the least
// depth of its texels: every fragment that can land in the tile later is nearer than, or as near
// as, that value, or it loses its depth test there. A node is skipped on a face when the nearest
// depth any point of its box can have (1/w at its least w) is below the least depth of every tile
// its texels lie in, by a margin that covers the float error of the fragments' depths. Tiles go
// stale as the buffer fills (their least depth only grows, so a stale value is conservative) and
// are refreshed when a test reads them after a leaf was drawn over them.
#include "internal.hpp"
#include "isa.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace hemilight {

namespace {

constexpr int tile_bits = 3;  // tiles of 8 x 8 texels
constexpr int tile_size = 1 << tile_bits;
// A fragment's depth is the triangle's plane evaluated per texel in float: its error is a few
// units in the last place of the row's terms. A node counts as hidden only when even its nearest
// point is farther than the occluders by this factor (1/64), far above that error.
constexpr float depth_margin = 1.0f + 1.0f / 64.0f;
// Texel rectangles are widened by this much (texels) beyond the node's projection: more than the
// rasterizer's snapping (1/512 texel) and the float error of the projection.
constexpr float rect_margin = 0.05f;

}  // namespace

void raster_detail::rasterizer_impl::occlusion_prepare() {
  const int tx = (n_ + tile_size - 1) >> tile_bits;
  tiles_x_ = tx;
  std::size_t total = 0;
  for (int f = 0; f < 5; ++f) {
    const int rows = f == 0 ? n_ : n_ / 2;
    tiles_y_[f] = (rows + tile_size - 1) >> tile_bits;
    tile_offset_[f] = total;
    total += static_cast<std::size_t>(tx) * static_cast<std::size_t>(tiles_y_[f]);
  }
  tile_depth_.assign(total, 0.0f);
  tile_dirty_.assign(total, 0);  // the buffer is empty: every tile's least depth is 0
  occluders_ = depth_.data();
}

void raster_detail::rasterizer_impl::occlusion_freeze() {
  frozen_depth_.assign(depth_.begin(), depth_.end());
  occluders_ = frozen_depth_.data();
  std::fill(tile_dirty_.begin(), tile_dirty_.end(), std::uint8_t(1));
}

void raster_detail::rasterizer_impl::redraw_prepare() {
  std::memset(depth_.data(), 0, depth_.size() * sizeof(float));
  draw_keys_.assign(1, 0u);
  draw_triangles_.assign(1, no_triangle);
  draws_.assign(1, draw_record{});
  draws_.front().index = no_triangle;
  ties_.clear();
}

bool raster_detail::rasterizer_impl::ties_decide_order() const {
  if (ties_.overflow) return true;
  // A tie decides nothing when the depth it tied at was beaten later, or when both fragments give
  // the texel the same bits: the same shade (radiance and flags) and, without a texture, the
  // distance comes from the texel's depth, which is the tied depth either way. (seen_triangle()
  // may then name either triangle.)
  // In a textured render the texel's radiance is the texture at the winner's UV (the resolve's
  // formula, fragment_radiance): the tie decides nothing when both fragments read the same bits.
  const auto key = [&](std::uint32_t id) { return key_bits_ ? id & ((1u << key_bits_) - 1u) : draw_keys_[id]; };
  for (const tie_log::entry& e : ties_.at) {
    if (*e.depth != e.z) continue;
    const std::size_t texel = static_cast<std::size_t>(e.depth - depth_.data());
    const std::uint32_t won = ids_[texel];
    if (key(won) != key(e.id)) return true;
    if (textured_) {
      const glm::vec3 a = fragment_radiance(won, texel, e.z, texture_), b = fragment_radiance(e.id, texel, e.z, texture_);
      if (std::memcmp(&a, &b, sizeof a) != 0) return true;
    }
  }
  return false;
}

// The reference order (traverse) visits the leaves depth first, left child first, and the BVH
// keeps each child's triangles in one run of scene::triangles(), the left child's first: it draws
// the opaque triangles in that order, each face's lanes in leaf order. At equal depths the first
// drawn keeps the texel, so among the fragments tied at a texel's final depth (the one that got
// there first in this pass and the later ones the log holds) the reference keeps the lowest
// position.
void raster_detail::rasterizer_impl::settle_ties() {
  const auto position = [&](std::uint32_t id) { return bvh_position_[draw_triangles_[key_bits_ ? id >> key_bits_ : id]]; };
  for (const tie_log::entry& e : ties_.at) {
    if (*e.depth != e.z) continue;
    ++stats_.occlusion_ties_settled;
    std::uint32_t& id = ids_[static_cast<std::size_t>(e.depth - depth_.data())];
    if (position(e.id) < position(id)) id = e.id;
  }
}

namespace {

// The least of the texels [x0, x1] (within one tile: x1 - x0 < 8) of rows y0..y1 of a face's
// depths d (rows of `width` texels; reading eight texels from x0 stays inside the buffer, which is
// padded by eight).
float least_in_rows(const float* d, int width, int x0, int x1, int y0, int y1) noexcept {
#if HEMILIGHT_RASTER_SSE2
  // Lanes outside [x0, x1] read +inf.
  const __m128 inf = _mm_set1_ps(INFINITY);
  const __m128i lane = _mm_setr_epi32(0, 1, 2, 3), count = _mm_set1_epi32(x1 - x0 + 1);
  const __m128 keep_lo = _mm_castsi128_ps(_mm_cmpgt_epi32(count, lane));
  const __m128 keep_hi = _mm_castsi128_ps(_mm_cmpgt_epi32(count, _mm_add_epi32(lane, _mm_set1_epi32(4))));
  __m128 least = inf;
  for (int y = y0; y <= y1; ++y) {
    const float* row = d + static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + x0;
    const __m128 a = _mm_or_ps(_mm_and_ps(keep_lo, _mm_loadu_ps(row)), _mm_andnot_ps(keep_lo, inf));
    const __m128 b = _mm_or_ps(_mm_and_ps(keep_hi, _mm_loadu_ps(row + 4)), _mm_andnot_ps(keep_hi, inf));
    least = _mm_min_ps(least, _mm_min_ps(a, b));
  }
  least = _mm_min_ps(least, _mm_shuffle_ps(least, least, _MM_SHUFFLE(1, 0, 3, 2)));
  least = _mm_min_ps(least, _mm_shuffle_ps(least, least, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtss_f32(least);
#else
  float least = INFINITY;
  for (int y = y0; y <= y1; ++y) {
    const float* row = d + static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
    for (int x = x0; x <= x1; ++x) least = std::min(least, row[x]);
  }
  return least;
#endif
}

// What face f sees of a box given by its eight corners in the local frame: a lower bound w_near
// of w over the part in the face's pyramid, and the bounds of the projection (u/w, v/w) of the
// box's part at w >= w_near; bounded = false when w_near does not pass the near plane.
struct face_projection {
  bool outside = false;  // the box is outside the face's pyramid: it covers none of its texels
  bool bounded = false;
  float w_near = 0.0f, u0 = 0.0f, u1 = 0.0f, v0 = 0.0f, v1 = 0.0f;
};

// to_clip's (u, v, w) per face: (x, y, z), (y, z, x), (-y, z, -x), (-x, z, y), (x, z, -y).
face_projection project_box(const float* lx, const float* ly, const float* lz, int f, float near) noexcept {
  face_projection p;
  const float* cu = f == 0 ? lx : f == 1 ? ly : f == 2 ? ly : lx;
  const float* cv = f == 0 ? ly : lz;
  const float* cw = f == 0 ? lz : f <= 2 ? lx : ly;
  const float su = f == 2 || f == 3 ? -1.0f : 1.0f, sw = f == 2 || f == 4 ? -1.0f : 1.0f;
  float u[8], v[8], w[8];
  float u_lo = INFINITY, u_hi = -INFINITY, v_lo = INFINITY, v_hi = -INFINITY, w_min = INFINITY;
  for (int k = 0; k < 8; ++k) {
    u[k] = su * cu[k];
    v[k] = cv[k];
    w[k] = sw * cw[k];
    u_lo = std::min(u_lo, u[k]);
    u_hi = std::max(u_hi, u[k]);
    v_lo = std::min(v_lo, v[k]);
    v_hi = std::max(v_hi, v[k]);
    w_min = std::min(w_min, w[k]);
  }
  // Outside the face's pyramid (w >= near, |u| <= w, |v| <= w): every corner beyond one plane.
  float out_w = -INFINITY, out_pu = -INFINITY, out_nu = -INFINITY, out_pv = -INFINITY, out_nv = -INFINITY;
  for (int k = 0; k < 8; ++k) {
    out_w = std::max(out_w, w[k]);
    out_pu = std::max(out_pu, w[k] - u[k]);
    out_nu = std::max(out_nu, w[k] + u[k]);
    out_pv = std::max(out_pv, w[k] - v[k]);
    out_nv = std::max(out_nv, w[k] + v[k]);
  }
  if (out_w < near || out_pu < 0.0f || out_nu < 0.0f || out_pv < 0.0f || out_nv < 0.0f) {
    p.outside = true;
    return p;
  }
  // What the face sees of the box lies in its pyramid |u|, |v| <= w (v >= 0 on the side faces):
  // there w >= |u| and w >= |v|, so w_near below bounds w over that part even when the box
  // reaches behind the face (a box beside the point, or across its tangent plane).
  const auto from_zero = [](float a, float b) { return a > 0.0f ? a : b < 0.0f ? -b : 0.0f; };
  const float v_from_zero = f == 0 ? from_zero(v_lo, v_hi) : std::max(v_lo, 0.0f);
  const float w_near = std::max(std::max(w_min, from_zero(u_lo, u_hi)), v_from_zero) * (1.0f - 1e-6f);
  if (!(w_near > near)) return p;
  // The projection of the box's part at w >= w_near: its corners there and the points where its
  // edges cross w = w_near (the vertices of a convex polytope; u/w takes its extremes at them).
  float u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
  const auto extend = [&](float pu, float pv) {
    u0 = std::min(u0, pu);
    u1 = std::max(u1, pu);
    v0 = std::min(v0, pv);
    v1 = std::max(v1, pv);
  };
  for (int k = 0; k < 8; ++k)
    if (w[k] >= w_near) extend(u[k] / w[k], v[k] / w[k]);
  if (w_min < w_near)
    for (int k = 0; k < 8; ++k)
      for (int bit = 1; bit < 8; bit <<= 1) {
        const int j = k | bit;
        if (j == k || (w[k] >= w_near) == (w[j] >= w_near)) continue;
        const float t = (w_near - w[k]) / (w[j] - w[k]);
        extend((u[k] + t * (u[j] - u[k])) / w_near, (v[k] + t * (v[j] - v[k])) / w_near);
      }
  p.bounded = true;
  p.w_near = w_near;
  p.u0 = u0;
  p.u1 = u1;
  p.v0 = v0;
  p.v1 = v1;
  return p;
}

#if HEMILIGHT_RASTER_AVX2
HEMILIGHT_TARGET_AVX2 inline float reduce_min(__m256 a) noexcept {
  __m128 m = _mm_min_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
  m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
  return _mm_cvtss_f32(_mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1))));
}

HEMILIGHT_TARGET_AVX2 inline float reduce_max(__m256 a) noexcept {
  __m128 m = _mm_max_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
  m = _mm_max_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
  return _mm_cvtss_f32(_mm_max_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1))));
}

// project_box with the eight corners in the lanes of one register per coordinate: the same
// operations on the same values, so the same bounds.
HEMILIGHT_TARGET_AVX2 face_projection project_box_avx2(const float* lx, const float* ly, const float* lz, int f,
                                                       float near) noexcept {
  face_projection p;
  const __m256 x = _mm256_loadu_ps(lx), y = _mm256_loadu_ps(ly), z = _mm256_loadu_ps(lz);
  const __m256 sign = _mm256_set1_ps(-0.0f);
  const __m256 u = f == 0 || f == 4 ? x : f == 1 ? y : f == 2 ? _mm256_xor_ps(y, sign) : _mm256_xor_ps(x, sign);
  const __m256 v = f == 0 ? y : z;
  const __m256 w = f == 0 ? z : f == 1 ? x : f == 2 ? _mm256_xor_ps(x, sign) : f == 3 ? y : _mm256_xor_ps(y, sign);
  const float u_lo = reduce_min(u), u_hi = reduce_max(u), v_lo = reduce_min(v), v_hi = reduce_max(v), w_min = reduce_min(w);
  // Outside the face's pyramid (w >= near, |u| <= w, |v| <= w): every corner beyond one plane.
  if (reduce_max(w) < near || reduce_max(_mm256_sub_ps(w, u)) < 0.0f || reduce_max(_mm256_add_ps(w, u)) < 0.0f ||
      reduce_max(_mm256_sub_ps(w, v)) < 0.0f || reduce_max(_mm256_add_ps(w, v)) < 0.0f) {
    p.outside = true;
    return p;
  }
  const auto from_zero = [](float a, float b) { return a > 0.0f ? a : b < 0.0f ? -b : 0.0f; };
  const float v_from_zero = f == 0 ? from_zero(v_lo, v_hi) : std::max(v_lo, 0.0f);
  const float w_near = std::max(std::max(w_min, from_zero(u_lo, u_hi)), v_from_zero) * (1.0f - 1e-6f);
  if (!(w_near > near)) return p;
  const __m256 wn = _mm256_set1_ps(w_near), inf = _mm256_set1_ps(INFINITY), ninf = _mm256_set1_ps(-INFINITY);
  // Corners at w >= w_near.
  const __m256 in = _mm256_cmp_ps(w, wn, _CMP_GE_OQ);
  const __m256 pu = _mm256_div_ps(u, w), pv = _mm256_div_ps(v, w);
  __m256 lo_u = _mm256_blendv_ps(inf, pu, in), hi_u = _mm256_blendv_ps(ninf, pu, in);
  __m256 lo_v = _mm256_blendv_ps(inf, pv, in), hi_v = _mm256_blendv_ps(ninf, pv, in);
  if (w_min < w_near) {
    // Edges crossing w = w_near: corner k and k ^ bit for bit = 1, 2, 4 (each edge twice).
    const __m256i partners[3] = {_mm256_setr_epi32(1, 0, 3, 2, 5, 4, 7, 6), _mm256_setr_epi32(2, 3, 0, 1, 6, 7, 4, 5),
                                 _mm256_setr_epi32(4, 5, 6, 7, 0, 1, 2, 3)};
    for (const __m256i& partner : partners) {
      const __m256 wj = _mm256_permutevar8x32_ps(w, partner), uj = _mm256_permutevar8x32_ps(u, partner),
                   vj = _mm256_permutevar8x32_ps(v, partner);
      const __m256 cross = _mm256_xor_ps(in, _mm256_cmp_ps(wj, wn, _CMP_GE_OQ));
      const __m256 t = _mm256_div_ps(_mm256_sub_ps(wn, w), _mm256_sub_ps(wj, w));
      const __m256 cu = _mm256_div_ps(_mm256_add_ps(u, _mm256_mul_ps(t, _mm256_sub_ps(uj, u))), wn);
      const __m256 cv = _mm256_div_ps(_mm256_add_ps(v, _mm256_mul_ps(t, _mm256_sub_ps(vj, v))), wn);
      lo_u = _mm256_min_ps(lo_u, _mm256_blendv_ps(inf, cu, cross));
      hi_u = _mm256_max_ps(hi_u, _mm256_blendv_ps(ninf, cu, cross));
      lo_v = _mm256_min_ps(lo_v, _mm256_blendv_ps(inf, cv, cross));
      hi_v = _mm256_max_ps(hi_v, _mm256_blendv_ps(ninf, cv, cross));
    }
  }
  p.bounded = true;
  p.w_near = w_near;
  p.u0 = reduce_min(lo_u);
  p.u1 = reduce_max(hi_u);
  p.v0 = reduce_min(lo_v);
  p.v1 = reduce_max(hi_v);
  return p;
}
#endif

// The corners of the box [lo, hi] (relative to the point) in the local frame (corner k takes x from
// hi if k & 1, y if k & 2, z if k & 4), as frame::to_local computes them.
void box_corners(const glm::vec3& lo, const glm::vec3& hi, const frame& basis, float* lx, float* ly, float* lz) noexcept {
  for (int k = 0; k < 8; ++k) {
    const float x = k & 1 ? hi.x : lo.x, y = k & 2 ? hi.y : lo.y, z = k & 4 ? hi.z : lo.z;
    lx[k] = basis.t.x * x + basis.t.y * y + basis.t.z * z;
    ly[k] = basis.b.x * x + basis.b.y * y + basis.b.z * z;
    lz[k] = basis.n.x * x + basis.n.y * y + basis.n.z * z;
  }
}

#if HEMILIGHT_RASTER_AVX2
// box_corners, eight lanes at once (the same operations: the same bits).
HEMILIGHT_TARGET_AVX2 void box_corners_avx2(const glm::vec3& lo, const glm::vec3& hi, const frame& basis, float* lx,
                                            float* ly, float* lz) noexcept {
  const __m256 x = _mm256_setr_ps(lo.x, hi.x, lo.x, hi.x, lo.x, hi.x, lo.x, hi.x);
  const __m256 y = _mm256_setr_ps(lo.y, lo.y, hi.y, hi.y, lo.y, lo.y, hi.y, hi.y);
  const __m256 z = _mm256_setr_ps(lo.z, lo.z, lo.z, lo.z, hi.z, hi.z, hi.z, hi.z);
  const auto dot = [&](const glm::vec3& a) HEMILIGHT_TARGET_AVX2 {
    return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(a.x), x), _mm256_mul_ps(_mm256_set1_ps(a.y), y)),
                         _mm256_mul_ps(_mm256_set1_ps(a.z), z));
  };
  _mm256_store_ps(lx, dot(basis.t));
  _mm256_store_ps(ly, dot(basis.b));
  _mm256_store_ps(lz, dot(basis.n));
}
#endif

}  // namespace

bool raster_detail::rasterizer_impl::hidden_in_tile(int face, int tx, int ty, int rx0, int rx1, int ry0, int ry1,
                                                    float nearest) {
  const std::size_t t = tile_offset_[face] + static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_) +
                        static_cast<std::size_t>(tx);
  const int rows = face == 0 ? n_ : n_ / 2;
  const int tile_x0 = tx << tile_bits, tile_y0 = ty << tile_bits;
  const int tile_x1 = std::min(tile_x0 + tile_size, n_) - 1, tile_y1 = std::min(tile_y0 + tile_size, rows) - 1;
  // A stale least depth is still a lower bound (depths only grow while drawing): enough to say
  // hidden; otherwise the tile is read again, or only the rectangle's part of it.
  if (nearest < tile_depth_[t]) return true;
  const float* d = occluders_ + hemicube_face_offset(n_, static_cast<hemicube_face>(face));
  const int x0 = std::max(rx0, tile_x0), x1 = std::min(rx1, tile_x1);
  const int y0 = std::max(ry0, tile_y0), y1 = std::min(ry1, tile_y1);
  const bool whole = x0 == tile_x0 && x1 == tile_x1 && y0 == tile_y0 && y1 == tile_y1;
  if (tile_dirty_[t] && whole) {
    tile_depth_[t] = least_in_rows(d, n_, tile_x0, tile_x1, tile_y0, tile_y1);
    tile_dirty_[t] = 0;
    return nearest < tile_depth_[t];
  }
  if (whole) return false;  // the tile's (current) least depth lies in the rectangle
  return nearest < least_in_rows(d, n_, x0, x1, y0, y1);
}

bool raster_detail::rasterizer_impl::texel_rect(int face, float u0, float u1, float v0, float v1, int& x0, int& x1, int& y0,
                                                int& y1) const {
  // Texel centres at (x + 1/2) for x = (u + 1) N / 2; side faces' rows start at v = 0. Widened by
  // rect_margin texels and the float error of the bounds.
  const int rows = face == 0 ? n_ : n_ / 2;
  if (std::isnan(u0) || std::isnan(u1) || std::isnan(v0) || std::isnan(v1)) {  // cannot happen; then: the whole face
    x0 = y0 = 0;
    x1 = n_ - 1;
    y1 = rows - 1;
    return true;
  }
  const float half = 0.5f * static_cast<float>(n_), v_offset = face == 0 ? 1.0f : 0.0f;
  const float fx0 = (u0 + 1.0f) * half - 0.5f, fx1 = (u1 + 1.0f) * half - 0.5f;
  const float fy0 = (v0 + v_offset) * half - 0.5f, fy1 = (v1 + v_offset) * half - 0.5f;
  const float m = rect_margin + 1e-5f * (std::fabs(fx0) + std::fabs(fx1) + std::fabs(fy0) + std::fabs(fy1));
  // ceil and floor of x clamped to [-1, count], by truncating x + 2 >= 1 (no libm call).
  const auto first = [](float x, int count) {
    const float c = std::min(std::max(x, -1.0f), static_cast<float>(count)) + 2.0f;
    const int t = static_cast<int>(c);
    return t + (static_cast<float>(t) < c ? 1 : 0) - 2;
  };
  const auto last = [](float x, int count) {
    return static_cast<int>(std::min(std::max(x, -1.0f), static_cast<float>(count)) + 2.0f) - 2;
  };
  x0 = std::max(first(fx0 - m, n_), 0);
  x1 = std::min(last(fx1 + m, n_), n_ - 1);
  y0 = std::max(first(fy0 - m, rows), 0);
  y1 = std::min(last(fy1 + m, rows), rows - 1);
  return x0 <= x1 && y0 <= y1;  // (false also for NaN bounds: nothing to draw either)
}

bool raster_detail::rasterizer_impl::rect_hidden(int face, int x0, int x1, int y0, int y1, float nearest) {
  // Hidden when `nearest` is below the depth of every texel of the rectangle, read per tile from
  // the tile's least depth where it is known and high enough.
  for (int ty = y0 >> tile_bits; ty <= (y1 >> tile_bits); ++ty) {
    const float* row = tile_depth_.data() + tile_offset_[face] + static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_);
    for (int tx = x0 >> tile_bits; tx <= (x1 >> tile_bits); ++tx)
      if (!(nearest < row[tx]) && !hidden_in_tile(face, tx, ty, x0, x1, y0, y1, nearest)) return false;
  }
  return true;
}

bool raster_detail::rasterizer_impl::triangle_hidden(int face, const clip_vertex (&c)[3]) {
  // As occlusion_test does for a box: w_near bounds w over the part of the triangle in the face's
  // pyramid, and the part at w >= w_near projects inside its vertices' and its edges' crossings.
  float u_lo = INFINITY, u_hi = -INFINITY, v_lo = INFINITY, v_hi = -INFINITY, w_min = INFINITY;
  for (const clip_vertex& q : c) {
    u_lo = std::min(u_lo, q.u);
    u_hi = std::max(u_hi, q.u);
    v_lo = std::min(v_lo, q.v);
    v_hi = std::max(v_hi, q.v);
    w_min = std::min(w_min, q.w);
  }
  const auto from_zero = [](float a, float b) { return a > 0.0f ? a : b < 0.0f ? -b : 0.0f; };
  const float v_from_zero = face == 0 ? from_zero(v_lo, v_hi) : std::max(v_lo, 0.0f);
  const float w_near = std::max(std::max(w_min, from_zero(u_lo, u_hi)), v_from_zero) * (1.0f - 1e-6f);
  if (!(w_near > near_)) return false;
  float u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
  for (int k = 0; k < 3; ++k) {
    const clip_vertex& a = c[k];
    const clip_vertex& b = c[k == 2 ? 0 : k + 1];
    if (a.w >= w_near) {
      u0 = std::min(u0, a.u / a.w);
      u1 = std::max(u1, a.u / a.w);
      v0 = std::min(v0, a.v / a.w);
      v1 = std::max(v1, a.v / a.w);
    }
    if ((a.w >= w_near) != (b.w >= w_near)) {
      const float t = (w_near - a.w) / (b.w - a.w);
      const float pu = (a.u + t * (b.u - a.u)) / w_near, pv = (a.v + t * (b.v - a.v)) / w_near;
      u0 = std::min(u0, pu);
      u1 = std::max(u1, pu);
      v0 = std::min(v0, pv);
      v1 = std::max(v1, pv);
    }
  }
  int x0, x1, y0, y1;
  if (!texel_rect(face, u0, u1, v0, v1, x0, x1, y0, y1)) return true;  // no texel centre under it
  return rect_hidden(face, x0, x1, y0, y1, depth_margin / w_near);
}

bool raster_detail::rasterizer_impl::plane_hidden(int face, const texel_box& box, const face_setup& fs) {
  // The plane's depth is affine in the texel indices: its largest over the box is at a corner.
  const double xs[2] = {static_cast<double>(box.x_begin), static_cast<double>(box.x_end)};
  double nearest = 0.0;
  for (const std::int64_t y : {box.y_begin, box.y_end})
    for (const double x : xs) nearest = std::max(nearest, fs.z00 + fs.dzdy * static_cast<double>(y) + double(fs.dzdx) * x);
  return rect_hidden(face, static_cast<int>(box.x_begin), static_cast<int>(box.x_end), static_cast<int>(box.y_begin),
                     static_cast<int>(box.y_end), static_cast<float>(nearest * depth_margin));
}

unsigned raster_detail::rasterizer_impl::occlusion_test(const bvh_node& node, unsigned mask, const glm::vec3& position,
                                                        const frame& basis, node_rects& rects, std::uint32_t triangles) {
  // The box's corners in the local frame, grown by the float error of moving points there (the
  // triangles' vertices carry the same kind of error), as eight lanes per coordinate (corner k
  // takes x from hi if k & 1, y if k & 2, z if k & 4): plain loops the compiler vectorises.
  const glm::vec3 scale = glm::max(glm::max(glm::abs(node.lo), glm::abs(node.hi)), glm::abs(position));
  const glm::vec3 grow(1e-6f * (scale.x + scale.y + scale.z));
  const glm::vec3 lo = node.lo - grow - position, hi = node.hi + grow - position;
  alignas(32) float lx[8], ly[8], lz[8];
#if HEMILIGHT_RASTER_AVX2
  if (avx2_)
    box_corners_avx2(lo, hi, basis, lx, ly, lz);
  else
#endif
    box_corners(lo, hi, basis, lx, ly, lz);
  unsigned hidden = 0;
  // Entirely below the tangent plane (every face sees z >= 0 only): nothing to draw.
  float z_max = lz[0];
  for (int k = 1; k < 8; ++k) z_max = std::max(z_max, lz[k]);
  if (z_max < 0.0f) return 0;
  for (int f = 0; f < 5; ++f) {
    if (!(mask >> f & 1u)) continue;
    const int rows = f == 0 ? n_ : n_ / 2;
    // The face's texels a point of the box may project to: all of them when the box reaches the
    // near plane (its projection is unbounded), else the bounds of its corners' projections (a
    // ratio over a box with positive denominators takes its extremes at the corners). to_clip's
    // (u, v, w) per face: (x, y, z), (y, z, x), (-y, z, -x), (-x, z, y), (x, z, -y).
    face_projection p;
#if HEMILIGHT_RASTER_AVX2
    if (avx2_)
      p = project_box_avx2(lx, ly, lz, f, near_);
    else
#endif
      p = project_box(lx, ly, lz, f, near_);
    if (p.outside) {
      mask &= ~(1u << f);
      continue;
    }
    if (!p.bounded) {
      rects.x0[f] = 0;
      rects.x1[f] = n_ - 1;
      rects.y0[f] = 0;
      rects.y1[f] = rows - 1;
      continue;  // its nearest depth is 1/near: nothing drawn can hide it
    }
    const float w_near = p.w_near, u0 = p.u0, u1 = p.u1, v0 = p.v0, v1 = p.v1;
    int x0, x1, y0, y1;
    if (!texel_rect(f, u0, u1, v0, v1, x0, x1, y0, y1)) {
      mask &= ~(1u << f);  // no texel centre under the node on this face
      continue;
    }
    rects.x0[f] = x0;
    rects.x1[f] = x1;
    rects.y0[f] = y0;
    rects.y1[f] = y1;
    // Hidden when its nearest depth, with the margin, is below the depth of every texel of its
    // rectangle, read per tile from the tile's least depth where it is known and high enough.
    if (rect_hidden(f, x0, x1, y0, y1, depth_margin / w_near)) {
      mask &= ~(1u << f);
      hidden |= 1u << f;
    }
  }
  if (!mask && hidden) {
    ++stats_.nodes_occluded;
    stats_.triangles_occluded += triangles;
  }
  return mask;
}

void raster_detail::rasterizer_impl::occlusion_drawn(unsigned mask, const node_rects& rects) {
  if (occluders_ != depth_.data()) return;  // frozen occluders do not change
  for (int f = 0; f < 5; ++f) {
    if (!(mask >> f & 1u)) continue;
    for (int ty = rects.y0[f] >> tile_bits; ty <= (rects.y1[f] >> tile_bits); ++ty) {
      std::uint8_t* row = tile_dirty_.data() + tile_offset_[f] + static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_);
      for (int tx = rects.x0[f] >> tile_bits; tx <= (rects.x1[f] >> tile_bits); ++tx) row[tx] = 1;
    }
  }
}

}  // namespace hemilight
