#include "hemilight/raster.hpp"

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <limits>
#include <string>

namespace hemilight {

namespace {

constexpr int sub_bits = 8;                   // sub-texel bits of the fixed-point grid
constexpr std::int64_t sub_one = 1 << sub_bits;
constexpr std::int64_t sub_half = sub_one / 2;
constexpr float guard_band = 2.0f;            // clip |u|, |v| <= 2 w: keeps fixed point bounded
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

// Signed distance to clip plane k (inside when >= 0).
inline float clip_distance(int k, const clip_vertex& c, float near) noexcept {
  switch (k) {
    case 0: return c.w - near;
    case 1: return guard_band * c.w - c.u;
    case 2: return guard_band * c.w + c.u;
    case 3: return guard_band * c.w - c.v;
    default: return guard_band * c.w + c.v;
  }
}

inline bool lex_less(const clip_vertex& a, const clip_vertex& b) noexcept {
  if (a.u != b.u) return a.u < b.u;
  if (a.v != b.v) return a.v < b.v;
  return a.w < b.w;
}

// The point where segment (a, b) crosses plane k. Computed from the endpoints in a canonical order
// so that two triangles sharing the edge get the same bits.
inline clip_vertex intersect(int k, clip_vertex a, clip_vertex b, float near) noexcept {
  if (lex_less(b, a)) std::swap(a, b);
  const float da = clip_distance(k, a, near), db = clip_distance(k, b, near);
  const float t = da / (da - db);
  return {a.u + t * (b.u - a.u), a.v + t * (b.v - a.v), a.w + t * (b.w - a.w)};
}

// Outcode bits of a local-frame point: bit 0 = below the tangent plane (z < 0), bits 1..12 the
// face-frustum side planes (a point outside bit k's plane sets it). Face f is rejected for a
// triangle when all three vertices share a bit of face_planes[f].
enum : unsigned {
  below = 1u << 0,
  x_lt_y = 1u << 1, x_lt_my = 1u << 2,  // x - y < 0,  x + y < 0
  mx_lt_y = 1u << 3, mx_lt_my = 1u << 4,  // -x - y < 0 (x + y > 0), -x + y < 0
  x_lt_z = 1u << 5, mx_lt_z = 1u << 6,    // x - z < 0, -x - z < 0
  y_lt_z = 1u << 7, my_lt_z = 1u << 8,    // y - z < 0, -y - z < 0
  z_lt_x = 1u << 9, z_lt_mx = 1u << 10,   // z - x < 0, z + x < 0
  z_lt_y = 1u << 11, z_lt_my = 1u << 12,  // z - y < 0, z + y < 0
};

// A face's frustum (with v >= 0 for side faces) is the set where none of its bits is set.
constexpr unsigned face_planes[5] = {
    z_lt_x | z_lt_mx | z_lt_y | z_lt_my,            // top: z >= |x|, z >= |y|
    below | x_lt_y | x_lt_my | x_lt_z,              // +x: x >= |y|, x >= z >= 0
    below | mx_lt_y | mx_lt_my | mx_lt_z,           // -x: -x >= |y|, -x >= z >= 0
    below | mx_lt_my | x_lt_my | y_lt_z,            // +y: y >= |x| (y - x >= 0 is -x + y; y + x >= 0), y >= z
    below | x_lt_y | mx_lt_y | my_lt_z,             // -y: -y >= |x|, -y >= z
};

inline unsigned outcode(const glm::vec3& p) noexcept {
  unsigned c = 0;
  if (p.z < 0) c |= below;
  if (p.x - p.y < 0) c |= x_lt_y;
  if (p.x + p.y < 0) c |= x_lt_my;
  if (-p.x - p.y < 0) c |= mx_lt_y;
  if (-p.x + p.y < 0) c |= mx_lt_my;
  if (p.x - p.z < 0) c |= x_lt_z;
  if (-p.x - p.z < 0) c |= mx_lt_z;
  if (p.y - p.z < 0) c |= y_lt_z;
  if (-p.y - p.z < 0) c |= my_lt_z;
  if (p.z - p.x < 0) c |= z_lt_x;
  if (p.z + p.x < 0) c |= z_lt_mx;
  if (p.z - p.y < 0) c |= z_lt_y;
  if (p.z + p.y < 0) c |= z_lt_my;
  return c;
}

// Faces whose frustum a world-space box may touch, given the local frame. Each local linear
// function f = d . (p - x) is bounded over the box by its value at the centre +- d_abs . half;
// the box is dropped from a face when one of the face's functions stays below -margin on it.
// The margin absorbs the rounding difference between this test and the per-vertex outcodes.
inline unsigned node_faces(const bvh_node& node, const glm::vec3& position, const frame& f) noexcept {
  const glm::vec3 c = 0.5f * (node.lo + node.hi) - position;
  const glm::vec3 h = 0.5f * (node.hi - node.lo);
  const float lx = glm::dot(f.t, c), ly = glm::dot(f.b, c), lz = glm::dot(f.n, c);
  const float rx = glm::dot(glm::abs(f.t), h), ry = glm::dot(glm::abs(f.b), h), rz = glm::dot(glm::abs(f.n), h);
  const float margin = 1e-5f * (std::fabs(lx) + std::fabs(ly) + std::fabs(lz) + rx + ry + rz);
  // Upper bounds of +-x +- y etc. over the box (a sum of radii bounds the radius of a sum).
  const auto out = [&](float centre, float radius) { return centre + radius < -margin; };
  if (out(lz, rz)) return 0;  // entirely below the tangent plane
  unsigned faces = 0;
  if (!(out(lz - lx, rz + rx) || out(lz + lx, rz + rx) || out(lz - ly, rz + ry) || out(lz + ly, rz + ry))) faces |= 1u;
  if (!(out(lx - ly, rx + ry) || out(lx + ly, rx + ry) || out(lx - lz, rx + rz))) faces |= 2u;
  if (!(out(-lx - ly, rx + ry) || out(-lx + ly, rx + ry) || out(-lx - lz, rx + rz))) faces |= 4u;
  if (!(out(ly - lx, rx + ry) || out(ly + lx, rx + ry) || out(ly - lz, ry + rz))) faces |= 8u;
  if (!(out(-ly - lx, rx + ry) || out(-ly + lx, rx + ry) || out(-ly - lz, ry + rz))) faces |= 16u;
  return faces;
}

// floor(a / 2^sub_bits) and ceil(a / 2^sub_bits) for any sign.
inline std::int64_t floor_sub(std::int64_t a) noexcept { return a >= 0 ? a / sub_one : -((-a + sub_one - 1) / sub_one); }
inline std::int64_t ceil_sub(std::int64_t a) noexcept { return -floor_sub(-a); }

struct fixed_point {
  std::int64_t x, y;
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// radiance_texture
// ---------------------------------------------------------------------------------------------

void radiance_texture::validate(const char* who) const {
  if (!pixels) throw_invalid_argument(std::string(who) + ": texture pixels is null");
  if (width <= 0 || height <= 0)
    throw_invalid_argument(std::string(who) + ": texture size " + std::to_string(width) + " x " +
                           std::to_string(height) + " is invalid; both must be positive");
  if (channels != 3 && channels != 4)
    throw_invalid_argument(std::string(who) + ": texture channels is " + std::to_string(channels) + "; it must be 3 or 4");
}

glm::vec3 radiance_texture::sample(const glm::vec2& uv) const noexcept {
  // Continuous texel coordinates (centres at integers), clamped to the edge centres: the same as
  // clamp-to-edge bilinear filtering; NaN fails both comparisons and lands on 0.
  float px = uv.x * static_cast<float>(width) - 0.5f, py = uv.y * static_cast<float>(height) - 0.5f;
  const float wmax = static_cast<float>(width - 1), hmax = static_cast<float>(height - 1);
  px = px > 0.0f ? (px < wmax ? px : wmax) : 0.0f;
  py = py > 0.0f ? (py < hmax ? py : hmax) : 0.0f;
  const int x0 = static_cast<int>(px), y0 = static_cast<int>(py);
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const float fx = px - static_cast<float>(x0), fy = py - static_cast<float>(y0);
  const auto at = [&](int x, int y) {
    const float* p = pixels + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) *
                                  static_cast<std::size_t>(channels);
    return glm::vec3(p[0], p[1], p[2]);
  };
  const glm::vec3 top = (1.0f - fx) * at(x0, y0) + fx * at(x1, y0);
  const glm::vec3 bottom = (1.0f - fx) * at(x0, y1) + fx * at(x1, y1);
  return (1.0f - fy) * top + fy * bottom;
}

float default_near_distance(const scene& s) noexcept {
  const float d = 1e-4f * s.size();
  return d > 0.0f ? d : 1e-4f;
}

// ---------------------------------------------------------------------------------------------
// hemicube_rasterizer
// ---------------------------------------------------------------------------------------------

hemicube_rasterizer::hemicube_rasterizer(std::shared_ptr<const scene> s, raster_options options) : scene_(std::move(s)) {
  if (!scene_) throw_invalid_argument("hemicube_rasterizer: scene is null");
  if (!std::isfinite(options.near_distance) || options.near_distance < 0.0f)
    throw_invalid_argument("hemicube_rasterizer: near_distance is " + std::to_string(options.near_distance) +
                           "; it must be finite and >= 0 (0 = default)");
  near_ = options.near_distance > 0.0f ? options.near_distance : default_near_distance(*scene_);
}

void hemicube_rasterizer::check_arguments(const char* who, const glm::vec3& position, const frame& basis,
                                          int resolution) const {
  const std::string w(who);
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(position[c]))
      throw_invalid_argument(w + ": position." + "xyz"[c] + " is " + std::to_string(position[c]) + "; it must be finite");
  const glm::vec3* axes[3] = {&basis.t, &basis.b, &basis.n};
  const char* names[3] = {"t", "b", "n"};
  for (int a = 0; a < 3; ++a) {
    const float len = glm::length(*axes[a]);
    if (!(std::fabs(len - 1.0f) <= 1e-3f))
      throw_invalid_argument(w + ": basis." + names[a] + " has length " + std::to_string(len) +
                             "; the frame must be orthonormal (tolerance 1e-3)");
  }
  const float dots[3] = {glm::dot(basis.t, basis.b), glm::dot(basis.t, basis.n), glm::dot(basis.b, basis.n)};
  const char* pairs[3] = {"t . b", "t . n", "b . n"};
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(dots[k]) <= 1e-3f))
      throw_invalid_argument(w + ": basis " + pairs[k] + " = " + std::to_string(dots[k]) +
                             "; the frame must be orthonormal (tolerance 1e-3)");
  if (!(glm::dot(glm::cross(basis.t, basis.b), basis.n) > 0.0f))
    throw_invalid_argument(w + ": basis is left-handed ((t x b) . n < 0); it must be right-handed");
  if (!is_valid_hemicube_resolution(resolution))
    throw_invalid_argument(w + ": resolution " + std::to_string(resolution) +
                           " is invalid: it must be even and in [2, 4096]");
}

void hemicube_rasterizer::prepare(int resolution) {
  const std::size_t count = hemicube_texel_count(resolution);
  if (n_ != resolution) {
    directions_.resize(count);
    lengths_.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      const hemicube_texel t = hemicube_texel_from_index(resolution, i);
      const glm::dvec2 c = hemicube_texel_min_corner(resolution, t) + glm::dvec2(1.0 / resolution);
      const glm::dvec3 d = hemicube_face_point(t.face, c.x, c.y);
      lengths_[i] = static_cast<float>(glm::length(d));
      directions_[i] = glm::vec3(glm::normalize(d));
    }
    n_ = resolution;
  }
  depth_.assign(count, 0.0f);
  ids_.resize(count);
  draws_.clear();
  stats_ = {};
}

std::uint32_t hemicube_rasterizer::seen_triangle(std::size_t texel) const noexcept {
  assert(texel < ids_.size());
  if (depth_[texel] == 0.0f) return no_triangle;
  return draws_[ids_[texel]].index;
}

template <hemicube_rasterizer::mode M>
void hemicube_rasterizer::draw_all(const glm::vec3& position, const frame& basis, const radiance_texture* texture) {
  const std::vector<bvh_node>& nodes = scene_->bvh();
  if (nodes.empty()) return;
  const std::vector<scene::triangle>& tris = scene_->triangles();
  // Stack entries: node index (low 27 bits are plenty: 2^31 triangles need < 2^29 nodes, so the
  // face mask travels in a second word).
  stack_.clear();
  stack_.push_back(0);
  stack_.push_back(31);
  while (!stack_.empty()) {
    const unsigned parent_mask = stack_.back();
    stack_.pop_back();
    const std::uint32_t ni = stack_.back();
    stack_.pop_back();
    const bvh_node& node = nodes[ni];
    ++stats_.nodes_visited;
    const unsigned mask = parent_mask & node_faces(node, position, basis);
    if (!mask) continue;
    if (node.count == 0) {
      stack_.push_back(node.first + 1);
      stack_.push_back(mask);
      stack_.push_back(node.first);
      stack_.push_back(mask);
      continue;
    }
    for (std::uint32_t k = 0; k < node.count; ++k) draw_triangle<M>(tris[node.first + k], mask, position, basis, texture);
  }
}

template <hemicube_rasterizer::mode M>
void hemicube_rasterizer::draw_triangle(const scene::triangle& tri, unsigned face_mask, const glm::vec3& position,
                                        const frame& basis, const radiance_texture* texture) {
  ++stats_.triangles_tested;
  const glm::vec3 local[3] = {basis.to_local(tri.v0 - position), basis.to_local(tri.v1 - position),
                              basis.to_local(tri.v2 - position)};
  const unsigned common = outcode(local[0]) & outcode(local[1]) & outcode(local[2]);
  unsigned faces = 0;
  for (int f = 0; f < 5; ++f)
    if ((face_mask >> f & 1u) && !(common & face_planes[f])) faces |= 1u << f;
  if (!faces) return;

  draw_record rec;
  // Edges and normal in world space (differences of the stored positions), then rotated.
  const glm::vec3 e1 = tri.v1 - tri.v0, e2 = tri.v2 - tri.v0;
  rec.normal = basis.to_local(glm::cross(e1, e2));
  rec.v0 = local[0];
  rec.plane = glm::dot(rec.normal, rec.v0);
  // A plane through the point is seen edge-on: it covers no texel centre.
  if (!(rec.plane != 0.0f) || !std::isfinite(rec.plane)) return;
  rec.index = tri.index;
  const material& m = scene_->triangle_material(tri.index);
  const bool back = rec.plane > 0.0f && !m.two_sided;
  rec.flags = back ? texel_back_face : texel_hit_front;
  rec.radiance = back ? glm::vec3(0.0f) : m.emission;
  rec.textured = !back && texture && scene_->has_lightmap_uvs();
  if (rec.textured) {
    const glm::vec3 le1 = basis.to_local(e1), le2 = basis.to_local(e2);
    const float nn = glm::dot(rec.normal, rec.normal);
    rec.grad_b1 = glm::cross(le2, rec.normal) / nn;
    rec.grad_b2 = glm::cross(rec.normal, le1) / nn;
  }
  const auto draw = static_cast<std::uint32_t>(draws_.size());
  draws_.push_back(rec);
  for (int f = 0; f < 5; ++f)
    if (faces >> f & 1u) {
      ++stats_.face_triangles;
      raster_face<M>(f, local, rec, draw);
    }
}

template <hemicube_rasterizer::mode M>
void hemicube_rasterizer::raster_face(int face, const glm::vec3 (&local)[3], const draw_record& rec,
                                      std::uint32_t draw) {
  const int n = n_;
  const int rows = face == 0 ? n : n / 2;
  const float near = near_;

  // Clip in homogeneous coordinates.
  clip_vertex poly[max_clip_vertices + 1], tmp[max_clip_vertices + 1];
  int count = 3;
  unsigned all_out = 31, any_out = 0;
  for (int i = 0; i < 3; ++i) {
    poly[i] = to_clip(face, local[i]);
    unsigned code = 0;
    for (int k = 0; k < 5; ++k)
      if (clip_distance(k, poly[i], near) < 0.0f) code |= 1u << k;
    all_out &= code;
    any_out |= code;
  }
  if (all_out) return;
  for (int k = 0; k < 5 && count >= 3; ++k) {
    if (!(any_out >> k & 1u)) continue;
    int out = 0;
    for (int i = 0; i < count; ++i) {
      const clip_vertex& a = poly[i];
      const clip_vertex& b = poly[(i + 1) % count];
      const bool ina = clip_distance(k, a, near) >= 0.0f, inb = clip_distance(k, b, near) >= 0.0f;
      if (ina) tmp[out++] = a;
      if (ina != inb) tmp[out++] = intersect(k, a, b, near);
    }
    std::copy(tmp, tmp + out, poly);
    count = out;
  }
  if (count < 3) return;

  // Project and snap. Side faces: v in [0, 1] maps to rows [0, N/2).
  const float half = 0.5f * static_cast<float>(n);
  const float v_offset = face == 0 ? 1.0f : 0.0f;
  fixed_point fx[max_clip_vertices + 1];
  for (int i = 0; i < count; ++i) {
    const float iw = 1.0f / poly[i].w;
    const float x = (poly[i].u * iw + 1.0f) * half * static_cast<float>(sub_one);
    const float y = (poly[i].v * iw + v_offset) * half * static_cast<float>(sub_one);
    fx[i] = {static_cast<std::int64_t>(std::lrint(x)), static_cast<std::int64_t>(std::lrint(y))};
  }

  // Depth 1/w of the triangle's plane at texel centres: with the plane n.p = k and
  // p = w (a + u c + v r), 1/w = (n.a + u n.c + v n.r) / k, affine in the texel indices.
  const clip_vertex nm = to_clip(face, rec.normal);  // (n.c, n.r, n.a)
  const double inv_k = 1.0 / static_cast<double>(rec.plane);
  const double step = 2.0 / n;
  const double u0 = 1.0 / n - 1.0, v0 = face == 0 ? 1.0 / n - 1.0 : 1.0 / n;
  const auto dzdx = static_cast<float>(nm.u * step * inv_k);
  const auto dzdy = static_cast<float>(nm.v * step * inv_k);
  const auto z00 = static_cast<float>((nm.w + nm.u * u0 + nm.v * v0) * inv_k);

  const std::size_t face_offset = hemicube_face_offset(n, static_cast<hemicube_face>(face));
  float* depth = depth_.data() + face_offset;
  std::uint32_t* ids = ids_.data() + face_offset;
  std::uint32_t* counts = M == mode::count ? counts_->data() + face_offset : nullptr;

  // Fan of the clipped polygon.
  for (int i = 1; i + 1 < count; ++i) {
    fixed_point p[3] = {fx[0], fx[i], fx[i + 1]};
    std::int64_t area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
    if (area == 0) continue;
    if (area < 0) std::swap(p[1], p[2]);
    const std::int64_t min_x = std::min({p[0].x, p[1].x, p[2].x}), max_x = std::max({p[0].x, p[1].x, p[2].x});
    const std::int64_t min_y = std::min({p[0].y, p[1].y, p[2].y}), max_y = std::max({p[0].y, p[1].y, p[2].y});
    // Texels whose centre (k + 1/2) lies in the box, clamped to the face.
    const std::int64_t x_begin = std::max<std::int64_t>(ceil_sub(min_x - sub_half), 0);
    const std::int64_t x_end = std::min<std::int64_t>(floor_sub(max_x - sub_half), n - 1);
    const std::int64_t y_begin = std::max<std::int64_t>(ceil_sub(min_y - sub_half), 0);
    const std::int64_t y_end = std::min<std::int64_t>(floor_sub(max_y - sub_half), rows - 1);
    if (x_begin > x_end || y_begin > y_end) continue;

    // Edge functions E(P) = d.x (P.y - A.y) - d.y (P.x - A.x) > 0 inside, d = B - A; at texel
    // (x, y): E = ex x + ey y + e0. Ties (E = 0) belong to edges with d.y > 0, or d.y = 0 and
    // d.x < 0: of two triangles sharing an edge exactly one owns it.
    std::int64_t ex[3], ey[3], e0[3];
    double inv_ex[3];
    for (int k = 0; k < 3; ++k) {
      const fixed_point& a = p[k];
      const fixed_point& b = p[(k + 1) % 3];
      const std::int64_t dx = b.x - a.x, dy = b.y - a.y;
      const bool owned = dy > 0 || (dy == 0 && dx < 0);
      ex[k] = -dy * sub_one;
      ey[k] = dx * sub_one;
      e0[k] = dx * (sub_half - a.y) - dy * (sub_half - a.x) - (owned ? 0 : 1);
      inv_ex[k] = ex[k] != 0 ? 1.0 / static_cast<double>(ex[k]) : 0.0;
    }
    for (std::int64_t y = y_begin; y <= y_end; ++y) {
      std::int64_t lo = x_begin, hi = x_end;
      for (int k = 0; k < 3 && lo <= hi; ++k) {
        const std::int64_t r = ey[k] * y + e0[k];  // E at x = 0 (with the tie bias)
        if (ex[k] > 0) {
          // r + ex x >= 0  <=>  x >= ceil(-r / ex): estimate in double, then make it exact.
          auto x = static_cast<std::int64_t>(std::ceil(static_cast<double>(-r) * inv_ex[k]));
          while (r + ex[k] * x < 0) ++x;
          while (r + ex[k] * (x - 1) >= 0) --x;
          lo = std::max(lo, x);
        } else if (ex[k] < 0) {
          // x <= floor(r / -ex)
          auto x = static_cast<std::int64_t>(std::floor(static_cast<double>(r) * -inv_ex[k]));
          while (r + ex[k] * x < 0) --x;
          while (r + ex[k] * (x + 1) >= 0) ++x;
          hi = std::min(hi, x);
        } else if (r < 0) {
          hi = lo - 1;
        }
      }
      if (lo > hi) continue;
      const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(n);
      if (M == mode::count) {
        for (std::int64_t x = lo; x <= hi; ++x) ++counts[row + static_cast<std::size_t>(x)];
        continue;
      }
      const float zrow = z00 + dzdy * static_cast<float>(y);
      float* drow = depth + row;
      std::uint32_t* irow = ids + row;
      for (std::int64_t x = lo; x <= hi; ++x) {
        float z = zrow + dzdx * static_cast<float>(x);
        // 1/w is positive on the triangle; rounding near an edge-on plane may say otherwise, and
        // a covered texel must still be covered: clamp to the smallest positive depth (farthest).
        z = z > FLT_MIN ? z : FLT_MIN;
        const auto xi = static_cast<std::size_t>(x);
        if (z > drow[xi]) {
          drow[xi] = z;
          irow[xi] = draw;
        }
      }
    }
  }
}

void hemicube_rasterizer::render(const glm::vec3& position, const frame& basis, int resolution, hemicube_buffer& out,
                                 const radiance_texture* texture) {
  const char* who = "hemicube_rasterizer::render";
  check_arguments(who, position, basis, resolution);
  if (texture) texture->validate(who);
  prepare(resolution);
  draw_all<mode::depth>(position, basis, texture);

  // Resolve: exact distance along the texel-centre ray, radiance, flags.
  out.resize(resolution);
  out.position = position;
  out.basis = basis;
  const glm::vec3 sky = scene_->sky_radiance();
  const std::size_t count = hemicube_texel_count(resolution);
  const std::vector<glm::vec2>& uvs = scene_->lightmap_uvs();
  const std::vector<std::uint32_t>& indices = scene_->indices();
  for (std::size_t i = 0; i < count; ++i) {
    float* rad = out.radiance.data() + 3 * i;
    if (depth_[i] == 0.0f) {
      rad[0] = sky.x;
      rad[1] = sky.y;
      rad[2] = sky.z;
      out.distance[i] = std::numeric_limits<float>::infinity();
      out.flags[i] = texel_miss;
      continue;
    }
    const draw_record& rec = draws_[ids_[i]];
    const glm::vec3& d = directions_[i];
    float t = rec.plane / glm::dot(rec.normal, d);
    // Ray nearly parallel to the plane: fall back to the rasterized depth (also exact in theory).
    if (!(t > 0.0f) || !(t < std::numeric_limits<float>::max())) t = lengths_[i] / depth_[i];
    out.distance[i] = t;
    out.flags[i] = rec.flags;
    glm::vec3 l = rec.radiance;
    if (rec.textured) {
      const glm::vec3 q = t * d - rec.v0;
      const float b1 = glm::dot(rec.grad_b1, q), b2 = glm::dot(rec.grad_b2, q);
      const std::size_t tri = 3 * static_cast<std::size_t>(rec.index);
      const glm::vec2& uv0 = uvs[indices[tri]];
      const glm::vec2 uv = uv0 + b1 * (uvs[indices[tri + 1]] - uv0) + b2 * (uvs[indices[tri + 2]] - uv0);
      l = texture->sample(uv);
    }
    rad[0] = l.x;
    rad[1] = l.y;
    rad[2] = l.z;
  }
}

void hemicube_rasterizer::render_coverage(const glm::vec3& position, const frame& basis, int resolution,
                                          std::vector<std::uint32_t>& counts) {
  check_arguments("hemicube_rasterizer::render_coverage", position, basis, resolution);
  prepare(resolution);
  counts.assign(hemicube_texel_count(resolution), 0u);
  counts_ = &counts;
  draw_all<mode::count>(position, basis, nullptr);
  counts_ = nullptr;
}

}  // namespace hemilight
