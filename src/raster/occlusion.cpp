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
  for (const auto& [depth, z] : ties_.at)
    if (*depth == z) return true;  // the tie holds the texel's final depth: the order chose its winner
  return false;
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

}  // namespace

bool raster_detail::rasterizer_impl::hidden_in_tile(int face, int tx, int ty, int rx0, int rx1, int ry0, int ry1,
                                                    float nearest) {
  const std::size_t t = tile_offset_[face] + static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_) +
                        static_cast<std::size_t>(tx);
  const int rows = face == 0 ? n_ : n_ / 2;
  const int tile_x0 = tx << tile_bits, tile_y0 = ty << tile_bits;
  const int tile_x1 = std::min(tile_x0 + tile_size, n_) - 1, tile_y1 = std::min(tile_y0 + tile_size, rows) - 1;
  const float* d = occluders_ + hemicube_face_offset(n_, static_cast<hemicube_face>(face));
  if (tile_dirty_[t]) {
    tile_depth_[t] = least_in_rows(d, n_, tile_x0, tile_x1, tile_y0, tile_y1);
    tile_dirty_[t] = 0;
  }
  if (nearest < tile_depth_[t]) return true;
  // The tile holds a texel as near as `nearest` (or an empty one): is it in the rectangle?
  const int x0 = std::max(rx0, tile_x0), x1 = std::min(rx1, tile_x1);
  const int y0 = std::max(ry0, tile_y0), y1 = std::min(ry1, tile_y1);
  if (x0 == tile_x0 && x1 == tile_x1 && y0 == tile_y0 && y1 == tile_y1) return false;
  return nearest < least_in_rows(d, n_, x0, x1, y0, y1);
}

bool raster_detail::rasterizer_impl::rect_hidden(int face, int x0, int x1, int y0, int y1, float nearest) {
  // Hidden when `nearest` is below the depth of every texel of the rectangle, read per tile from
  // the tile's least depth where it is known and high enough.
  for (int ty = y0 >> tile_bits; ty <= (y1 >> tile_bits); ++ty)
    for (int tx = x0 >> tile_bits; tx <= (x1 >> tile_bits); ++tx)
      if (!hidden_in_tile(face, tx, ty, x0, x1, y0, y1, nearest)) return false;
  return true;
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
                                                        const frame& basis, node_rects& rects) {
  // The box's corners in the local frame, grown by the float error of moving points there (the
  // triangles' vertices carry the same kind of error), as eight lanes per coordinate (corner k
  // takes x from hi if k & 1, y if k & 2, z if k & 4): plain loops the compiler vectorises.
  const glm::vec3 scale = glm::max(glm::max(glm::abs(node.lo), glm::abs(node.hi)), glm::abs(position));
  const glm::vec3 grow(1e-6f * (scale.x + scale.y + scale.z));
  const glm::vec3 lo = node.lo - grow - position, hi = node.hi + grow - position;
  float lx[8], ly[8], lz[8];
  for (int k = 0; k < 8; ++k) {
    const float x = k & 1 ? hi.x : lo.x, y = k & 2 ? hi.y : lo.y, z = k & 4 ? hi.z : lo.z;
    lx[k] = basis.t.x * x + basis.t.y * y + basis.t.z * z;
    ly[k] = basis.b.x * x + basis.b.y * y + basis.b.z * z;
    lz[k] = basis.n.x * x + basis.n.y * y + basis.n.z * z;
  }
  const float n = static_cast<float>(n_), half = 0.5f * n;
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
    if (!p.bounded) {
      rects.x0[f] = 0;
      rects.x1[f] = n_ - 1;
      rects.y0[f] = 0;
      rects.y1[f] = rows - 1;
      continue;  // its nearest depth is 1/near: nothing drawn can hide it
    }
    const float w_near = p.w_near, u0 = p.u0, u1 = p.u1, v0 = p.v0, v1 = p.v1;
    // Texel centres at (x + 1/2) for x = (u + 1) N / 2; side faces' rows start at v = 0.
    const float v_offset = f == 0 ? 1.0f : 0.0f;
    const float fx0 = (u0 + 1.0f) * half - 0.5f, fx1 = (u1 + 1.0f) * half - 0.5f;
    const float fy0 = (v0 + v_offset) * half - 0.5f, fy1 = (v1 + v_offset) * half - 0.5f;
    const float m = rect_margin + 1e-5f * (std::fabs(fx0) + std::fabs(fx1) + std::fabs(fy0) + std::fabs(fy1));
    const auto first = [](float x, int count) {
      return static_cast<std::int32_t>(std::ceil(std::min(std::max(x, -1.0f), static_cast<float>(count))));
    };
    const auto last = [](float x, int count) {
      return static_cast<std::int32_t>(std::floor(std::min(std::max(x, -1.0f), static_cast<float>(count))));
    };
    const std::int32_t x0 = std::max(first(fx0 - m, n_), 0), x1 = std::min(last(fx1 + m, n_), n_ - 1);
    const std::int32_t y0 = std::max(first(fy0 - m, rows), 0), y1 = std::min(last(fy1 + m, rows), rows - 1);
    if (x0 > x1 || y0 > y1) {
      mask &= ~(1u << f);  // no texel centre under the node on this face
      continue;
    }
    rects.x0[f] = x0;
    rects.x1[f] = x1;
    rects.y0[f] = y0;
    rects.y1[f] = y1;
    // Hidden when its nearest depth, with the margin, is below the depth of every texel of its
    // rectangle, read per tile from the tile's least depth where it is known and high enough.
    if (rect_hidden(f, x0, x1, y0, y1, depth_margin / w_near)) mask &= ~(1u << f);
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
