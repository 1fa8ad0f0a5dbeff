// Internal to the rasterizer (src/raster*.cpp): the fixed-point grid, the faces' clip space and
// the per-(triangle, face) depth set-up, shared by the coverage paths (raster.cpp) and exact edge
// coverage (raster_edge.cpp). Not installed.
#pragma once

#include "hemilight/raster.hpp"

#include <cstdint>

#include <glm/glm.hpp>

namespace hemilight {

namespace raster_detail {

constexpr int sub_bits = 8;                   // sub-texel bits of the fixed-point grid
constexpr std::int64_t sub_one = 1 << sub_bits;
constexpr std::int64_t sub_half = sub_one / 2;
// Guard band: clip |u|, |v| <= 1000 w. Wide, so that big triangles crossing a face's edges are
// rarely clipped (clipping multiplies the rows to walk), narrow enough that snapped coordinates
// stay below 1001 * 2048 * 256 < 2^29 for N <= 4096 (edge-function terms below 2^60 in int64).
constexpr float guard_band = 1000.0f;
constexpr int max_clip_vertices = 3 + 5;      // each of the 5 clip planes adds at most one

// A vertex in a face's clip space: u = c.p, v = r.p, w = a.p (geometry.hpp face axes).
struct clip_vertex {
  float u, v, w;
};

// The local-frame point p seen on face f, as (c.p, r.p, a.p). Exact (sign changes, permutation).
inline clip_vertex to_clip(int face, const glm::vec3& p) noexcept {
  switch (face) {
    case 0: return {p.x, p.y, p.z};
    case 1: return {p.y, p.z, p.x};
    case 2: return {-p.y, p.z, -p.x};
    case 3: return {-p.x, p.z, p.y};
    default: return {p.x, p.z, -p.y};
  }
}

// floor(a / 2^sub_bits) and ceil(a / 2^sub_bits) for any sign.
// (Arithmetic right shift: floor for negative values too; every supported compiler does this,
// and C++20 requires it.)
inline std::int64_t floor_sub(std::int64_t a) noexcept { return a >> sub_bits; }
inline std::int64_t ceil_sub(std::int64_t a) noexcept { return -floor_sub(-a); }

}  // namespace raster_detail

// The depth plane of one (triangle, face) pair, computed when the pair first covers a texel.
struct hemicube_rasterizer::face_setup {
  bool ready = false;
  double z00 = 0.0, dzdy = 0.0;
  float dzdx = 0.0f;

  // step = 2 / N, u0 = 1 / N - 1: the texel pitch and the first texel centre in face units
  // (hemicube_rasterizer::prepare computes them once per resolution).
  void prepare(int face, double step, double u0, const draw_record& rec) noexcept {
    if (ready) return;
    // Depth 1/w of the triangle's plane at texel centres: with the plane n.p = k and
    // p = w (a + u c + v r), 1/w = (n.a + u n.c + v n.r) / k, affine in the texel indices.
    // Evaluated per row in double, then per texel in float.
    const raster_detail::clip_vertex nm = raster_detail::to_clip(face, rec.normal);  // (n.c, n.r, n.a)
    const double inv_k = 1.0 / static_cast<double>(rec.plane);
    const double v0 = face == 0 ? u0 : 0.5 * step;  // side faces: rows start at v = 0
    dzdx = static_cast<float>(nm.u * step * inv_k);
    dzdy = nm.v * step * inv_k;
    z00 = (nm.w + nm.u * u0 + nm.v * v0) * inv_k;
    ready = true;
  }
};

}  // namespace hemilight
