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
  ties_ = 0;
}

float raster_detail::rasterizer_impl::tile_least_depth(int face, int tx, int ty) {
  const std::size_t t = tile_offset_[face] + static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_) +
                        static_cast<std::size_t>(tx);
  if (!tile_dirty_[t]) return tile_depth_[t];
  const int rows = face == 0 ? n_ : n_ / 2;
  const int x0 = tx * tile_size, x1 = std::min(x0 + tile_size, n_);
  const int y0 = ty * tile_size, y1 = std::min(y0 + tile_size, rows);
  const float* d = occluders_ + hemicube_face_offset(n_, static_cast<hemicube_face>(face));
  float least = d[static_cast<std::size_t>(y0) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(x0)];
  for (int y = y0; y < y1 && least > 0.0f; ++y) {
    const float* row = d + static_cast<std::size_t>(y) * static_cast<std::size_t>(n_);
    for (int x = x0; x < x1; ++x) least = std::min(least, row[x]);
  }
  tile_depth_[t] = least;
  tile_dirty_[t] = 0;
  return least;
}

unsigned raster_detail::rasterizer_impl::occlusion_test(const bvh_node& node, unsigned mask, const glm::vec3& position,
                                                        const frame& basis, node_rects& rects) {
  // The box's corners in the local frame, grown by the float error of moving points there (the
  // triangles' vertices carry the same kind of error).
  const glm::vec3 scale = glm::max(glm::max(glm::abs(node.lo), glm::abs(node.hi)), glm::abs(position));
  const glm::vec3 grow(1e-6f * (scale.x + scale.y + scale.z));
  const glm::vec3 lo = node.lo - grow, hi = node.hi + grow;
  glm::vec3 corner[8];
  for (int k = 0; k < 8; ++k)
    corner[k] = basis.to_local(glm::vec3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z) - position);
  const float n = static_cast<float>(n_), half = 0.5f * n;
  for (int f = 0; f < 5; ++f) {
    if (!(mask >> f & 1u)) continue;
    const int rows = f == 0 ? n_ : n_ / 2;
    // The face's texels a point of the box may project to: all of them when the box reaches the
    // near plane (its projection is unbounded), else the bounds of its corners' projections (a
    // ratio over a box with positive denominators takes its extremes at the corners).
    float w_min = INFINITY, u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    for (const glm::vec3& c : corner) {
      const clip_vertex cv = to_clip(f, c);
      w_min = std::min(w_min, cv.w);
      if (cv.w > 0.0f) {
        const float inv = 1.0f / cv.w;
        u0 = std::min(u0, cv.u * inv);
        u1 = std::max(u1, cv.u * inv);
        v0 = std::min(v0, cv.v * inv);
        v1 = std::max(v1, cv.v * inv);
      }
    }
    if (!(w_min > near_)) {
      rects.x0[f] = 0;
      rects.x1[f] = n_ - 1;
      rects.y0[f] = 0;
      rects.y1[f] = rows - 1;
      continue;  // its nearest depth is 1/near: nothing drawn can hide it
    }
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
    // rectangle: read per tile from the tile's least depth, and texel by texel where a tile
    // (partly outside the rectangle) holds a nearer or empty texel.
    const float nearest = depth_margin / w_min;
    const float* d = occluders_ + hemicube_face_offset(n_, static_cast<hemicube_face>(f));
    bool hidden = true;
    for (int ty = y0 >> tile_bits; hidden && ty <= (y1 >> tile_bits); ++ty)
      for (int tx = x0 >> tile_bits; hidden && tx <= (x1 >> tile_bits); ++tx) {
        if (nearest < tile_least_depth(f, tx, ty)) continue;
        const int cx0 = std::max(x0, tx << tile_bits), cx1 = std::min(x1, (tx << tile_bits) + tile_size - 1);
        const int cy0 = std::max(y0, ty << tile_bits), cy1 = std::min(y1, (ty << tile_bits) + tile_size - 1);
        for (int y = cy0; hidden && y <= cy1; ++y) {
          const float* row = d + static_cast<std::size_t>(y) * static_cast<std::size_t>(n_);
          for (int x = cx0; x <= cx1; ++x)
            if (!(nearest < row[x])) {
              hidden = false;
              break;
            }
        }
      }
    if (hidden) mask &= ~(1u << f);
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
