// The fallback ray queries (rays_internal.hpp): the scene's own BVH (the rasterizer's, 32-triangle
// leaves), Woop, Benthin and Wald's watertight triangle test, a leaf's triangles in vectorised loops
// (#pragma omp simd), and an ordered traversal with a fixed stack. rays.cpp answers through Embree
// and comes here only when its Embree scene could not be built.
//
// Same contract as rays.hpp's occluded() and intersect(): hits at 0 < t < t_max (both exclusive,
// t in units of |direction|), either face, no hit for a zero or non-finite direction or origin, a
// NaN t_max or t_max <= 0. Traversal: the slab test with a precomputed reciprocal direction
// (components of |d| < 1e-30 are treated as 1e-30 with their sign) and the far distance scaled by
// 1 + 2 gamma(3) (Ize 2013), so rounding never culls a box the ray touches; ordered, with a fixed
// stack of 64 entries (the BVH's depth is at most 27). The triangle test's edge functions are
// evaluated in float and, when one is exactly 0, again in double (exact): a ray through a shared
// edge or vertex hits at least one of its triangles. Ties in intersect: the first in BVH order
// among those in the first leaf that reaches that t.
//
// Compiled with -ffp-contract=off (CMakeLists.txt): the edge functions of two triangles that share
// an edge must be exact negations of each other, which a fused multiply-add would break.
#include "ray_accel.hpp"
#include "../scene/scene_access.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>


namespace hemilight {

namespace {

constexpr float infinity = std::numeric_limits<float>::infinity();
constexpr int stack_capacity = 64;
// 1 + 2 gamma(3), gamma(n) = n u / (1 - n u), u = 2^-24 (Ize 2013), rounded up.
constexpr float far_scale = 1.0000004f;
constexpr float min_abs_direction = 1e-30f;

// Everything a query derives from its ray once.
struct ray_setup {
  float o[3];    // origin, permuted axes (kx, ky, kz)
  float sx, sy, sz;
  float ow[3];   // origin, world axes (boxes)
  float inv[3];  // reciprocal direction, world axes (boxes)
  const float* c[3][3];  // c[vertex][i]: coordinate array of axis k_i (i = 0: kx, 1: ky, 2: kz)
};

bool make_setup(const scene& s, const glm::vec3& origin, const glm::vec3& d, float t_max, ray_setup& r) noexcept {
  if (!(t_max > 0.0f) || s.bvh().empty()) return false;
  const glm::vec3 a = glm::abs(d);
  const float m = std::max(a.x, std::max(a.y, a.z));
  if (!(m > 0.0f) || !std::isfinite(m) || !std::isfinite(d.x + d.y + d.z)) return false;
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z)) return false;
  const int kz = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
  const int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  const int k[3] = {kx, ky, kz};
  for (int i = 0; i < 3; ++i) {
    r.o[i] = origin[k[i]];
    r.ow[i] = origin[i];
    const float di = std::fabs(d[i]) < min_abs_direction ? std::copysign(min_abs_direction, d[i]) : d[i];
    r.inv[i] = 1.0f / di;
    for (int v = 0; v < 3; ++v) r.c[v][i] = detail::scene_access::vertex_coordinates(s, v, k[i]);
  }
  r.sx = d[kx] / d[kz];
  r.sy = d[ky] / d[kz];
  r.sz = 1.0f / d[kz];
  return true;
}

// Slab test of a node's box against [0, t_max]; t_near is where the ray enters it.
inline bool hit_box(const bvh_node& b, const ray_setup& r, float t_max, float& t_near) noexcept {
  const float x0 = (b.lo.x - r.ow[0]) * r.inv[0], x1 = (b.hi.x - r.ow[0]) * r.inv[0];
  const float y0 = (b.lo.y - r.ow[1]) * r.inv[1], y1 = (b.hi.y - r.ow[1]) * r.inv[1];
  const float z0 = (b.lo.z - r.ow[2]) * r.inv[2], z1 = (b.hi.z - r.ow[2]) * r.inv[2];
  const float tn = std::max(std::max(std::min(x0, x1), std::min(y0, y1)), std::max(std::min(z0, z1), 0.0f));
  const float tf = std::min(std::min(std::max(x0, x1), std::max(y0, y1)), std::max(z0, z1)) * far_scale;
  t_near = tn;
  return tn <= std::min(tf, t_max);
}

// The sheared vertex coordinates of one triangle (Woop et al., section 3).
struct sheared {
  float ax, ay, az, bx, by, bz, cx, cy, cz;
};

inline sheared shear(const ray_setup& r, std::uint32_t i) noexcept {
  sheared t;
  t.az = r.c[0][2][i] - r.o[2];
  t.bz = r.c[1][2][i] - r.o[2];
  t.cz = r.c[2][2][i] - r.o[2];
  t.ax = (r.c[0][0][i] - r.o[0]) - r.sx * t.az;
  t.ay = (r.c[0][1][i] - r.o[1]) - r.sy * t.az;
  t.bx = (r.c[1][0][i] - r.o[0]) - r.sx * t.bz;
  t.by = (r.c[1][1][i] - r.o[1]) - r.sy * t.bz;
  t.cx = (r.c[2][0][i] - r.o[0]) - r.sx * t.cz;
  t.cy = (r.c[2][1][i] - r.o[1]) - r.sy * t.cz;
  return t;
}

// The exact path of one triangle (an edge function was 0 in float): edge functions in double
// from the same float sheared coordinates. Returns t, or +inf for a miss.
float exact_triangle(const ray_setup& r, std::uint32_t i, float t_max) noexcept {
  const sheared s = shear(r, i);
  const double u = double(s.cx) * double(s.by) - double(s.cy) * double(s.bx);
  const double v = double(s.ax) * double(s.cy) - double(s.ay) * double(s.cx);
  const double w = double(s.bx) * double(s.ay) - double(s.by) * double(s.ax);
  if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return infinity;
  const double det = u + v + w;
  if (det == 0.0) return infinity;
  const double t = double(r.sz) * (u * double(s.az) + v * double(s.bz) + w * double(s.cz)) / det;
  return t > 0.0 && t < double(t_max) ? static_cast<float>(t) : infinity;
}

// One lane of the leaf loops: Woop, Benthin and Wald's edge functions in float for triangle
// first + j. hit: inside (no mixed signs), det != 0 and 0 < t < t_max, with t = tt / ad; zero: an
// edge function is exactly 0 (the exact retry decides).
struct lane_result {
  int hit, zero;
  float tt, ad;
};
inline lane_result lane(const ray_setup& r, std::uint32_t first, std::uint32_t j, std::uint32_t count, float t_max) noexcept {
  const sheared s = shear(r, first + j);
  const float u = s.cx * s.by - s.cy * s.bx;
  const float v = s.ax * s.cy - s.ay * s.cx;
  const float w = s.bx * s.ay - s.by * s.ax;
  const int live = j < count;
  const int neg = (u < 0.0f) | (v < 0.0f) | (w < 0.0f);
  const int pos = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
  const float det = u + v + w;
  const float t = r.sz * (u * s.az + v * s.bz + w * s.cz);
  const float sign = det < 0.0f ? -1.0f : 1.0f;
  const float tt = t * sign, ad = det * sign;
  return {live & (1 - (neg & pos)) & (det != 0.0f) & (tt > 0.0f) & (tt < t_max * ad),
          live & ((u == 0.0f) | (v == 0.0f) | (w == 0.0f)), tt, ad};
}

// Any-hit over a leaf: eight lanes at a time (lanes past `count` read the next triangles or the
// padding of the coordinate arrays and are masked out).
inline bool leaf_any(const ray_setup& r, std::uint32_t first, std::uint32_t count, float t_max) noexcept {
  const std::uint32_t n8 = (count + 7u) & ~7u;
  int hit = 0, zero = 0;
#pragma omp simd reduction(| : hit, zero)
  for (std::uint32_t j = 0; j < n8; ++j) {
    const lane_result l = lane(r, first, j, count, t_max);
    hit |= l.hit;
    zero |= l.zero;
  }
  if (hit) return true;
  if (!zero) return false;
  for (std::uint32_t j = 0; j < count; ++j)
    if (exact_triangle(r, first + j, t_max) < infinity) return true;
  return false;
}

// Closest hit over a leaf: the smallest t below `best` (first in leaf order on ties); returns
// the triangle's index or UINT32_MAX.
inline std::uint32_t leaf_closest(const ray_setup& r, std::uint32_t first, std::uint32_t count,
                                            float& best) noexcept {
  alignas(32) float ts[scene::max_leaf_triangles + 8];
  const std::uint32_t n8 = (count + 7u) & ~7u;
  const float t_max = best;
  int zero = 0;
#pragma omp simd reduction(| : zero)
  for (std::uint32_t j = 0; j < n8; ++j) {
    const lane_result l = lane(r, first, j, count, t_max);
    zero |= l.zero;
    ts[j] = l.hit ? l.tt / l.ad : infinity;
  }
  if (zero)
    for (std::uint32_t j = 0; j < count; ++j) ts[j] = exact_triangle(r, first + j, t_max);
  std::uint32_t found = UINT32_MAX;
  for (std::uint32_t j = 0; j < count; ++j)
    if (ts[j] < best) {
      best = ts[j];
      found = first + j;
    }
  return found;
}

template <bool any>
inline bool traverse(const scene& s, const ray_setup& r, float t_max, std::uint32_t* closest,
                               float* closest_t) noexcept {
  const bvh_node* nodes = s.bvh().data();
  struct entry {
    std::uint32_t node;
    float t_near;
  };
  entry stack[stack_capacity];
  int top = 0;
  float best = t_max;
  std::uint32_t found = UINT32_MAX;
  float t_root;
  if (!hit_box(nodes[0], r, best, t_root)) return false;
  std::uint32_t node = 0;
  for (;;) {
    const bvh_node& nd = nodes[node];
    if (nd.count > 0) {
      if (any) {
        if (leaf_any(r, nd.first, nd.count, t_max)) return true;
      } else {
        const std::uint32_t f = leaf_closest(r, nd.first, nd.count, best);
        if (f != UINT32_MAX) found = f;
      }
    } else {
      std::uint32_t near_child = nd.first, far_child = nd.first + 1;
      float tn0, tn1;
      const bool h0 = hit_box(nodes[near_child], r, best, tn0);
      const bool h1 = hit_box(nodes[far_child], r, best, tn1);
      if (h0 && h1) {
        if (tn1 < tn0) {
          std::swap(near_child, far_child);
          std::swap(tn0, tn1);
        }
        stack[top++] = {far_child, tn1};
        node = near_child;
        continue;
      }
      if (h0 || h1) {
        node = h0 ? near_child : far_child;
        continue;
      }
    }
    for (;;) {
      if (top == 0) {
        if (!any && found != UINT32_MAX) {
          *closest = found;
          *closest_t = best;
          return true;
        }
        return false;
      }
      const entry e = stack[--top];
      if (any || e.t_near <= best) {
        node = e.node;
        break;
      }
    }
  }
}


inline bool any_hit(const scene& s, const ray_setup& r, float t_max) noexcept {
  return traverse<true>(s, r, t_max, nullptr, nullptr);
}
inline bool closest_hit(const scene& s, const ray_setup& r, float t_max, std::uint32_t* i, float* t) noexcept {
  return traverse<false>(s, r, t_max, i, t);
}

}  // namespace

namespace detail {

bool occluded_bvh(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept {
  ray_setup r;
  if (!make_setup(s, origin, direction, t_max, r)) return false;
  return any_hit(s, r, t_max);
}

bool intersect_bvh(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max,
                   ray_hit& hit) noexcept {
  ray_setup r;
  if (!make_setup(s, origin, direction, t_max, r)) return false;
  std::uint32_t i = 0;
  float t = 0.0f;
  if (!closest_hit(s, r, t_max, &i, &t)) return false;
  const scene::triangle& tri = s.triangles()[i];
  hit.distance = t;
  hit.drawable = i;
  hit.triangle = tri.index;
  hit.front_face = glm::dot(glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0), direction) < 0.0f;
  return true;
}

}  // namespace detail

}  // namespace hemilight
