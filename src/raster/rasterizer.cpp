// The hemicube rasterizer (raster.hpp): binding, traversal and culling, clipping and snapping,
// the coverage paths of one triangle (draw_fixed) and the resolve. The SIMD kernel sets it
// dispatches to are in kernels_sse2.hpp, kernels_avx2.hpp and leaf_avx.inl (one translation unit,
// so the kernels inline where their target allows); exact edge coverage is in edge_coverage.cpp.
#include "hemilight/raster.hpp"
#include "internal.hpp"
#include "lod.hpp"
#include "../scene/scene_access.hpp"

#include "hemilight/cubemap.hpp"

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <limits>
#include <cstring>
#include <string>

#include "isa.hpp"
#include "kernel_common.hpp"
#include "kernels_sse2.hpp"
#include "kernels_avx2.hpp"

namespace hemilight {

using namespace raster_detail;

namespace {

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
#if HEMILIGHT_RASTER_SSE2
  return outcode_sse2(p);  // the same bits
#else
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
#endif
}

// Faces whose frustum a world-space box may touch, given the local frame. Each local linear
// function f = d . (p - x) is bounded over the box by its value at the centre +- d_abs . half;
// the box is dropped from a face when one of the face's functions stays below -margin on it.
// The margin absorbs the rounding difference between this test and the per-vertex outcodes.
// Squared distance from a point to a node's box (0 inside): the front-to-back order's key.
inline float box_distance2(const bvh_node& node, const glm::vec3& p) noexcept {
  const glm::vec3 d = glm::max(glm::max(node.lo - p, p - node.hi), glm::vec3(0.0f));
  return glm::dot(d, d);
}

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




// The resolve loops, with restrict pointers so that the byte stores of the flags do not force
// reloads (char stores may alias anything). Texels never written have depth 0 (their id is
// stale): they are set to draw 0, the sky. keys[id]: the draw's entry in shades. The radiance is
// planar (hemicube_buffer).
void resolve_texels(std::size_t count, float* __restrict depth, const float* __restrict lengths,
                    std::uint32_t* __restrict ids, const shade* __restrict shades,
                    key_map key_of, float* __restrict distance, float* __restrict red, float* __restrict green,
                    float* __restrict blue, std::uint8_t* __restrict flags, bool simd) noexcept {
  std::size_t i = 0;
#if HEMILIGHT_RASTER_SSE2
  if (simd) i = resolve_texels_sse2(count, depth, lengths, ids, shades, key_of, distance, red, green, blue, flags);
#endif
  // Scalar reference (and tail): the same values.
  for (; i < count; ++i) {
    distance[i] = lengths[i] / depth[i];  // +inf for 1/w = 0
    ids[i] = depth[i] > 0.0f ? ids[i] : 0u;  // ids of texels never written are stale
    depth[i] = 0.0f;                         // cleared for the next render
    const std::uint32_t key = key_of(ids[i]);
    copy_shades(&key, 1, shades, red + i, green + i, blue + i, flags + i);
  }
}

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

const raster_detail::triangle_keys& raster_detail::triangle_keys_of(const scene& s) {
  detail::lazy_slot* slot = detail::derived_access::of(s, detail::derived_kind::raster_keys);
  if (!slot->done.load(std::memory_order_acquire))
    std::call_once(slot->once, [&] {
      auto keys = std::make_shared<triangle_keys>();
      keys->front_key.resize(s.triangle_count());
      for (std::size_t i = 0; i < s.triangle_count(); ++i)
        keys->front_key[i] = (2u + s.emission_index(i)) << 1 | (s.triangle_material(i).two_sided ? 0u : 1u);
      keys->position.assign(s.triangle_count(), hemicube_rasterizer::no_triangle);
      for (std::size_t i = 0; i < s.triangles().size(); ++i) keys->position[s.triangles()[i].index] = static_cast<std::uint32_t>(i);
      slot->value = std::move(keys);
      slot->done.store(true, std::memory_order_release);
    });
  return *static_cast<const triangle_keys*>(slot->value.get());
}

float default_near_distance(const scene& s) noexcept {
  const float d = 1e-4f * s.size();
  return d > 0.0f ? d : 1e-4f;
}

// ---------------------------------------------------------------------------------------------
// hemicube_rasterizer
// ---------------------------------------------------------------------------------------------

hemicube_rasterizer::hemicube_rasterizer(std::shared_ptr<const scene> s, raster_options options)
    : impl_(std::make_unique<rasterizer_impl>()) {
  impl_->bind(std::move(s), options);
}

hemicube_rasterizer::hemicube_rasterizer(const hemicube_rasterizer& other)
    : impl_(other.impl_ ? std::make_unique<rasterizer_impl>(*other.impl_) : nullptr) {}
hemicube_rasterizer::hemicube_rasterizer(hemicube_rasterizer&& other) noexcept = default;
hemicube_rasterizer& hemicube_rasterizer::operator=(const hemicube_rasterizer& other) {
  if (this != &other) impl_ = other.impl_ ? std::make_unique<rasterizer_impl>(*other.impl_) : nullptr;
  return *this;
}
hemicube_rasterizer& hemicube_rasterizer::operator=(hemicube_rasterizer&& other) noexcept = default;
hemicube_rasterizer::~hemicube_rasterizer() = default;

void hemicube_rasterizer::bind(std::shared_ptr<const scene> s, const raster_options& options) {
  if (impl_) {
    impl_->bind(std::move(s), options);
    return;
  }
  // A moved-from rasterizer: a new state, kept only if the bind succeeds.
  auto fresh = std::make_unique<rasterizer_impl>();
  fresh->bind(std::move(s), options);
  impl_ = std::move(fresh);
}

void hemicube_rasterizer::unbind() noexcept {
  if (impl_) impl_->unbind();
}

// A moved-from rasterizer has no state: it renders nothing, like an unbound one.
static rasterizer_impl& bound_state(const std::unique_ptr<rasterizer_impl>& impl, const char* who) {
  if (!impl) throw_invalid_argument(std::string(who) + ": no scene (the rasterizer was moved from; bind() one first)");
  return *impl;
}

void hemicube_rasterizer::render(const glm::vec3& position, const frame& basis, int resolution, hemicube_buffer& out,
                                 const radiance_texture* texture) {
  bound_state(impl_, "hemicube_rasterizer::render").render(position, basis, resolution, out, texture);
}

void hemicube_rasterizer::render_coverage(const glm::vec3& position, const frame& basis, int resolution,
                                          std::vector<std::uint32_t>& counts) {
  bound_state(impl_, "hemicube_rasterizer::render_coverage").render_coverage(position, basis, resolution, counts);
}

std::uint32_t hemicube_rasterizer::seen_triangle(std::size_t texel) const noexcept {
  assert(impl_);
  return impl_->seen_triangle(texel);
}

float hemicube_rasterizer::near_distance() const noexcept { return impl_ ? impl_->near_distance() : 0.0f; }

const raster_statistics& hemicube_rasterizer::statistics() const noexcept {
  static const raster_statistics none{};
  return impl_ ? impl_->statistics() : none;
}

const std::shared_ptr<const scene>& hemicube_rasterizer::scene_ptr() const noexcept {
  static const std::shared_ptr<const scene> none;
  return impl_ ? impl_->scene_ptr() : none;
}

// ---------------------------------------------------------------------------------------------
// rasterizer_impl: set-up
// ---------------------------------------------------------------------------------------------

void validate_raster_options(const raster_options& options, const std::string& who) {
  if (!std::isfinite(options.near_distance) || options.near_distance < 0.0f)
    throw_invalid_argument(who + ": near_distance is " + std::to_string(options.near_distance) +
                           "; it must be finite and >= 0 (0 = default)");
  if (!(options.lod_texels >= 0.0f && options.lod_texels <= 16.0f))
    throw_invalid_argument(who + ": lod_texels is " + std::to_string(options.lod_texels) + "; it must be in [0, 16] (0 = off)");
  if (options.sky) {
    // A cheap structural check; the values were checked when the map was built (from_image).
    const cubemap& m = *options.sky;
    if (m.level_count() < 1 || m.levels[0].size < 1 || (m.channels() != 3 && m.channels() != 4) ||
        m.levels[0].pixels.size() != 6u * std::size_t(m.size()) * std::size_t(m.size()) * std::size_t(m.channels()))
      throw_invalid_argument(who + ": the sky cube map is empty or inconsistent (build it with cubemap::from_image)");
  }
}

void raster_detail::rasterizer_impl::unbind() noexcept {
  scene_.reset();
  sky_.reset();
  front_keys_ = bvh_position_ = nullptr;  // the scene's (triangle_keys_of)
}

void raster_detail::rasterizer_impl::bind(std::shared_ptr<const scene> s, const raster_options& options) {
  // Step 1: every check before any member changes (a failed bind leaves the rasterizer as it was).
  if (!s) throw_invalid_argument("hemicube_rasterizer: scene is null");
  validate_raster_options(options, "hemicube_rasterizer");
  // triangle_keys packs 2 + an emission index and a flag in 32 bits (a scene with 2^30 distinct
  // emissions would need over 100 GB).
  if (s->emissions().size() >= (std::size_t(1) << 30))
    throw_invalid_argument("hemicube_rasterizer: the scene has " + std::to_string(s->emissions().size()) +
                           " distinct emissions; at most 2^30 - 1 are supported");
  // Step 2: the scene, the options, and the shades (the direction tables and scratch stay).
  scene_ = std::move(s);
  near_ = options.near_distance > 0.0f ? options.near_distance : default_near_distance(*scene_);
  simd_ = options.diagnostics.simd;
#if HEMILIGHT_RASTER_AVX2
  avx2_ = options.diagnostics.simd && options.diagnostics.avx2 && __builtin_cpu_supports("avx2");
  avx512_ = avx2_ && options.diagnostics.avx512 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
            __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
#endif
  sky_ = options.sky;
  edge_ = options.edge_coverage;
  lod_texels_ = edge_ ? 0.0f : options.lod_texels;
  lod_ = lod_texels_ > 0.0f ? &lod_proxies_of(*scene_) : nullptr;
  occlusion_ = options.diagnostics.occlusion_culling &&
               scene_->drawable_triangle_count() >= options.diagnostics.occlusion_min_triangles;
  // Per node, the triangles below it (children follow their parent in the array).
  const std::vector<bvh_node>& nodes = scene_->bvh();
  subtree_triangles_.assign(nodes.size(), 0u);
  for (std::size_t i = nodes.size(); i-- > 0;)
    subtree_triangles_[i] = nodes[i].count ? nodes[i].count
                                           : subtree_triangles_[nodes[i].first] + subtree_triangles_[nodes[i].first + 1];

  const glm::vec3 sky = scene_->sky_radiance();
  shades_.clear();
  shades_.reserve(2 + scene_->emissions().size());
  shades_.push_back({sky.x, sky.y, sky.z, texel_miss});
  shades_.push_back({0.0f, 0.0f, 0.0f, texel_back_face});
  for (const glm::vec3& e : scene_->emissions()) shades_.push_back({e.x, e.y, e.z, texel_hit_front});
  const triangle_keys& keys = triangle_keys_of(*scene_);  // step 1 checked that the keys fit
  front_keys_ = keys.front_key.data();
  bvh_position_ = keys.position.data();
  // The back of a one-sided see-through triangle: black, but not a back face to the tests for
  // texels inside geometry (a card or a pane is no closed surface). Only when the scene has them.
  see_through_back_key_ = static_cast<std::uint32_t>(shades_.size());
  if (!scene_->see_through_triangles().empty()) shades_.push_back({0.0f, 0.0f, 0.0f, texel_hit_front});
  // Texel ids are draw << key_bits_ | key when both fit in 31 bits (draws: at most one per
  // drawable triangle, plus draw 0); the resolve then reads the key from the id instead of
  // looking it up per draw (a gather per group of eight texels). Ids stay below 2^31: the
  // resolve's "no run" marker is all ones.
  std::uint32_t bits = 1;
  while ((std::size_t(1) << bits) < shades_.size()) ++bits;
  // With edge coverage a draw is a (triangle, face) pair (draw numbers then follow the drawing
  // order within each face, which the edge resolve's ties need): up to five per triangle.
  const std::size_t draws = scene_->drawable_triangle_count() * (edge_ ? 5 : 1) + 1;
  key_bits_ = bits < 31 && draws <= (std::size_t(1) << (31 - bits)) ? bits : 0;
  edges_.table = edge_ ? &edge_table_of(*scene_) : nullptr;
  edges_.facing.assign(edge_ ? edges_.table->planes.size() : 0, 0);
}

void raster_detail::rasterizer_impl::check_arguments(const char* who, const glm::vec3& position, const frame& basis,
                                          int resolution) const {
  const std::string w(who);
  if (!scene_) throw_invalid_argument(w + ": no scene (unbind() was called; bind() one first)");
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
  check_hemicube_resolution(resolution, who);
}

void raster_detail::rasterizer_impl::prepare(int resolution) {
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
    texel_step_ = 2.0 / resolution;
    first_centre_ = 1.0 / resolution - 1.0;
  }
  // Padded by 8 texels: the AVX2 kernels may load and store back up to 7 texels past a row's end.
  // The resolve clears what it reads, so after a render the buffer is already zero.
  if (!depth_clear_ || depth_.size() != count + 8) {
    depth_.resize(count + 8);
    std::memset(depth_.data(), 0, depth_.size() * sizeof(float));  // 0.0f is all zero bits
  }
  depth_clear_ = false;  // drawing is about to write it
  ids_.resize(count + 8);  // stale ids are masked by depth 0 (never written)
  // Draw 0 stands for "nothing hit" (the sky): texels start there.
  draw_keys_.assign(1, 0u);
  draw_triangles_.assign(1, no_triangle);
  draws_.assign(1, draw_record{});
  draws_.front().index = no_triangle;
  stats_ = {};
  ties_.clear();
  ties_.limit = 2 * count;
  tiles_ready_ = false;
  tie_sink_ = nullptr;  // set by draw_all while occlusion culling draws front to back
  if (edge_) edge_prepare(count, resolution);
}

std::uint32_t raster_detail::rasterizer_impl::seen_triangle(std::size_t texel) const noexcept {
  assert(texel < hemicube_texel_count(n_));
  return draw_triangles_[ids_[texel] >> key_bits_];  // the resolve set unwritten texels to draw 0
}

unsigned raster_detail::rasterizer_impl::drop_faces_between_texel_centres(const bvh_node& node, unsigned mask,
                                                               const glm::vec3& position, const frame& basis,
                                                               bool hard) const {
  // A node far away compared with its size may fall between texel centres on every face it
  // touches: then none of its triangles can cover a centre. Bound the node by its bounding
  // sphere (centre c, radius R, local frame); on a face where it lies in front of the near plane,
  // u = c.p / a.p over the sphere is bounded by the corners of (c.c +- R) / (a.c -+ R) (a ratio
  // over a box with positive denominators takes its extremes at the corners). The margin (1/50
  // texel) exceeds the rasterizer's snapping (1/512 texel) and the float error of this test, so
  // the culling never changes a rendered texel.
  const glm::vec3 centre = 0.5f * (node.lo + node.hi);
  const glm::vec3 c = basis.to_local(centre - position);
  // Grown by the float error of moving points to the local frame (the triangles' vertices carry
  // the same kind of error, ~1 ulp of the world coordinates): far from the origin it matters.
  const glm::vec3 scale = glm::max(glm::abs(centre), glm::abs(position));
  const float radius = 0.5f * glm::length(node.hi - node.lo) + 1e-6f * (scale.x + scale.y + scale.z);
  const float n = static_cast<float>(n_);
  // Every face's test below needs radius * n <= 4 w, and w <= |c| on every face: a node that big
  // for its distance (all nodes of a room around the point) is kept without the per-face work.
  if (radius * n > 4.0f * (std::fabs(c.x) + std::fabs(c.y) + std::fabs(c.z))) return mask;
  const float margin = 0.02f;
  for (int f = 0; f < 5; ++f) {
    if (!(mask >> f & 1u)) continue;
    const clip_vertex cc = to_clip(f, c);
    // Only nodes that span a few texels at most (and are in front of the near plane).
    if (!(cc.w - radius >= near_) || radius * n > 4.0f * cc.w) continue;
    const float inv_near = 1.0f / (cc.w - radius), inv_far = 1.0f / (cc.w + radius);
    const float u0 = std::min((cc.u - radius) * inv_near, (cc.u - radius) * inv_far);
    const float u1 = std::max((cc.u + radius) * inv_near, (cc.u + radius) * inv_far);
    const float v0 = std::min((cc.v - radius) * inv_near, (cc.v - radius) * inv_far);
    const float v1 = std::max((cc.v + radius) * inv_near, (cc.v + radius) * inv_far);
    // Texel coordinates; centres at k + 1/2. Relative float error of the bounds is ~1e-6.
    const float half = 0.5f * n, v_offset = f == 0 ? 1.0f : 0.0f;
    const float x0 = (u0 + 1.0f) * half, x1 = (u1 + 1.0f) * half;
    const float y0 = (v0 + v_offset) * half, y1 = (v1 + v_offset) * half;
    const float m = margin + 1e-5f * (std::fabs(x0) + std::fabs(x1) + std::fabs(y0) + std::fabs(y1));
    // Is there an integer k in the face with x0 - m <= k + 1/2 <= x1 + m? The range is a few
    // texels wide; clamped to the face (a little beyond it), floor is a truncation of a positive
    // value (no libm call).
    const float rows = f == 0 ? n : half;
    const auto has_centre = [](float lo, float hi, float count) {
      // Integers K = k + 2 in [a, b] with K in [2, count + 1]; a, b shifted to be >= 1.
      const float a = std::max(lo - 0.5f, -1.0f) + 2.0f, b = std::min(hi - 0.5f, count) + 2.0f;
      if (!(b >= 2.0f) || !(a <= b)) return false;  // also false for NaN
      const int floor_b = static_cast<int>(b);      // truncation = floor (b > 0)
      const int ceil_a = static_cast<int>(a) + (static_cast<float>(static_cast<int>(a)) < a ? 1 : 0);
      return std::max(ceil_a, 2) <= std::min(floor_b, static_cast<int>(count) + 1);
    };
    if (has_centre(x0 - m, x1 + m, n) && has_centre(y0 - m, y1 + m, rows)) continue;
    // With edge coverage a node between texel centres still covers parts of texels: kept where
    // those may be hard (the texels its bounds overlap, widened by the margin).
    if (hard && (edges_.hard_faces >> f & 1u)) {
      const auto clamp_index = [](float x, float count) {
        return static_cast<std::int64_t>(std::floor(std::min(std::max(x, -1.0f), count)));
      };
      const std::int64_t c0 = std::max<std::int64_t>(clamp_index(x0 - m, n), 0);
      const std::int64_t c1 = std::min<std::int64_t>(clamp_index(x1 + m, n), n_ - 1);
      const std::int64_t r0 = std::max<std::int64_t>(clamp_index(y0 - m, rows), 0);
      const std::int64_t r1 = std::min<std::int64_t>(clamp_index(y1 + m, rows), static_cast<std::int64_t>(rows) - 1);
      if (c0 <= c1 && r0 <= r1 && edge_box_is_hard(f, c0, c1, r0, r1)) continue;
    }
    mask &= ~(1u << f);
  }
  return mask;
}



template <rasterizer_impl::mode M>
void raster_detail::rasterizer_impl::draw_all(const glm::vec3& position, const frame& basis) {
  if (scene_->bvh().empty()) return;
  if (M == mode::depth && occlusion_ && !edge_) {
    // Occlusion culling (occlusion.cpp): front to back, each node tested against the tiles of what
    // is drawn. A texel's winner is its nearest fragment in any order, unless two fragments tie,
    // which the reference order decides (the first drawn wins): the logged ties are settled in
    // place (settle_ties), or with level of detail or an overflowed log the render is drawn again
    // in that order, culled against the depths found (final: a node behind them neither wins nor
    // ties). Either way the buffer is the one the unculled reference order gives, bit for bit.
    occlusion_prepare();
    tiles_ready_ = true;
    tie_sink_ = &ties_;
    culling_ = true;
    traverse_front_to_back(position, basis);
    tie_sink_ = nullptr;
    if (!ties_.overflow && !lod_) {
      settle_ties();
    } else if (ties_decide_order()) {
      ++stats_.occlusion_redraws;
      occlusion_freeze();
      redraw_prepare();
      traverse<M>(position, basis, true);
    }
    culling_ = false;
    return;
  }
  traverse<M>(position, basis, false);
}

template <rasterizer_impl::mode M>
inline void raster_detail::rasterizer_impl::draw_leaf(const bvh_node& node, unsigned mask, const glm::vec3& position,
                                               const frame& basis, const simd_frame& sf) {
  const std::vector<scene::triangle>& tris = scene_->triangles();
#if HEMILIGHT_RASTER_AVX2
  if (avx2_) {
    const bool log = M == mode::depth && tie_sink_;
    for (std::uint32_t k = 0; k < node.count; k += 8) {
      const std::uint32_t first = node.first + k, count = std::min<std::uint32_t>(8, node.count - k);
      if (log)
        avx512_ ? draw_leaf_avx512<M, true>(tris.data(), first, count, mask, sf, basis)
                : draw_leaf_avx2<M, true>(tris.data(), first, count, mask, sf, basis);
      else
        avx512_ ? draw_leaf_avx512<M, false>(tris.data(), first, count, mask, sf, basis)
                : draw_leaf_avx2<M, false>(tris.data(), first, count, mask, sf, basis);
    }
    return;
  }
#else
  (void)sf;
#endif
  for (std::uint32_t k = 0; k < node.count; ++k) draw_triangle<M>(tris[node.first + k], mask, position, basis);
}

// The reference order: depth first, left to right. With `cull`, nodes are tested against the
// occluders too (the redraw after a tie, against the frozen depths of the front-to-back pass).
template <rasterizer_impl::mode M>
void raster_detail::rasterizer_impl::traverse(const glm::vec3& position, const frame& basis, bool cull) {
  const std::vector<bvh_node>& nodes = scene_->bvh();
  simd_frame sf;
#if HEMILIGHT_RASTER_AVX2
  if (avx2_) sf.set(position, basis, *scene_);
#endif
  // Stack entries: node index << 5 | the faces it may touch.
  stack_.clear();
  stack_.push_back(31);
  node_rects rects;
  while (!stack_.empty()) {
    const std::uint64_t entry = stack_.back();
    stack_.pop_back();
    const auto ni = static_cast<std::uint32_t>(entry >> 5);
    const bvh_node& node = nodes[ni];
    ++stats_.nodes_visited;
    unsigned mask = static_cast<unsigned>(entry & 31u) & node_faces(node, position, basis);
    if (mask) mask = drop_faces_between_texel_centres(node, mask, position, basis, M == mode::depth && edge_);
    if (mask && cull) mask = occlusion_test(node, mask, position, basis, rects, subtree_triangles_[ni]);
    if (!mask) continue;
    if (M == mode::depth && lod_ && lod_draw(node, ni, mask, position, basis)) continue;
    if (node.count == 0) {
      stack_.push_back(std::uint64_t(node.first + 1) << 5 | mask);  // popped after the left child's subtree
      stack_.push_back(std::uint64_t(node.first) << 5 | mask);
      continue;
    }
    draw_leaf<M>(node, mask, position, basis, sf);
  }
}

// Level of detail: a node whose box spans under lod_texels_ texels (its half diagonal R seen from
// distance d > 2 R: R N / d texels, the angle of 2R over the 2/N of a texel at a face's centre) is
// drawn from its proxy (lod.hpp), when it has one smaller than itself. True when drawn so.
bool raster_detail::rasterizer_impl::lod_draw(const bvh_node& node, std::uint32_t node_index, unsigned mask,
                                              const glm::vec3& position, const frame& basis) {
  const std::uint32_t count = lod_->count[node_index];
  if (count == 0 || count >= subtree_triangles_[node_index]) return false;
  const float r = 0.5f * glm::length(node.hi - node.lo);
  const float d = glm::length(0.5f * (node.lo + node.hi) - position);
  if (!(d > 2.0f * r) || !(r * static_cast<float>(n_) < lod_texels_ * d)) return false;
  ++stats_.lod_nodes;
  const std::uint32_t first = lod_->first[node_index];
  for (std::uint32_t k = first; k < first + count; ++k)
    draw_triangle<mode::depth>(lod_->triangles[k], mask, position, basis, lod_->vertices[k].data());
  return true;
}

// Front to back, best first: the node whose box is nearest to the point (ties: the lower index),
// so that near occluders are drawn before what they hide anywhere in the tree. Each node is tested
// against the faces' frusta and texel centres and against the occluders by occlusion_test alone
// (a conservative test of its own: the reference order's node_faces and between-centres tests
// would only repeat it).
void raster_detail::rasterizer_impl::traverse_front_to_back(const glm::vec3& position, const frame& basis) {
  const std::vector<bvh_node>& nodes = scene_->bvh();
  simd_frame sf;
#if HEMILIGHT_RASTER_AVX2
  if (avx2_) sf.set(position, basis, *scene_);
#endif
  // Heap keys: the squared distance's bits (non-negative floats order as their bits), the node
  // index, the faces: the least key is the nearest node.
  const auto key = [&](std::uint32_t ni, unsigned mask) {
    std::uint32_t bits;
    const float d2 = box_distance2(nodes[ni], position);
    std::memcpy(&bits, &d2, sizeof bits);
    return std::uint64_t(bits) << 32 | std::uint64_t(ni) << 5 | mask;
  };
  stack_.clear();
  stack_.push_back(31);
  const std::greater<std::uint64_t> later;
  node_rects rects;
  while (!stack_.empty()) {
    std::pop_heap(stack_.begin(), stack_.end(), later);
    const std::uint64_t entry = stack_.back();
    stack_.pop_back();
    const auto ni = static_cast<std::uint32_t>(entry >> 5 & 0x7ffffffu);
    const bvh_node& node = nodes[ni];
    ++stats_.nodes_visited;
    const unsigned mask = occlusion_test(node, static_cast<unsigned>(entry & 31u), position, basis, rects, subtree_triangles_[ni]);
    if (!mask) continue;
    if (lod_ && lod_draw(node, ni, mask, position, basis)) {
      occlusion_drawn(mask, rects);
      continue;
    }
    if (node.count == 0) {
      for (std::uint32_t c = node.first; c <= node.first + 1; ++c) {
        stack_.push_back(key(c, mask));
        std::push_heap(stack_.begin(), stack_.end(), later);
      }
      continue;
    }
    draw_leaf<mode::depth>(node, mask, position, basis, sf);
    occlusion_drawn(mask, rects);
  }
}

template <rasterizer_impl::mode M>
void raster_detail::rasterizer_impl::draw_triangle(const scene::triangle& tri, unsigned face_mask, const glm::vec3& position,
                                        const frame& basis, const std::uint32_t* vertices) {
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
  rec.vertices = vertices;
  // The rest of the record (material, texture gradients) is filled in when the triangle first
  // covers a texel centre: most triangles of big scenes cover none.
  std::uint32_t draw = 0;
  for (int f = 0; f < 5; ++f)
    if (faces >> f & 1u) {
      ++stats_.face_triangles;
      if (M == mode::depth && edge_) draw = 0;  // one draw per face (see bind)
      raster_face<M>(f, local, rec, draw, basis, tri);
    }
}

#if HEMILIGHT_RASTER_AVX2
#define HEMILIGHT_LEAF_NAME draw_leaf_avx2
#define HEMILIGHT_LEAF_TARGET HEMILIGHT_TARGET_AVX2
#define HEMILIGHT_LEAF_WIDE 0
#include "leaf_avx.inl"
#undef HEMILIGHT_LEAF_NAME
#undef HEMILIGHT_LEAF_TARGET
#undef HEMILIGHT_LEAF_WIDE
#define HEMILIGHT_LEAF_NAME draw_leaf_avx512
#define HEMILIGHT_LEAF_TARGET HEMILIGHT_TARGET_AVX512
#define HEMILIGHT_LEAF_WIDE 1
#include "leaf_avx.inl"
#undef HEMILIGHT_LEAF_NAME
#undef HEMILIGHT_LEAF_TARGET
#undef HEMILIGHT_LEAF_WIDE
#endif

#if defined(__GNUC__) || defined(__clang__)
// Inlined into the set-up: called once per drawn triangle, where a call's saves and restores
// were a fifth of its cost.
__attribute__((always_inline))
#endif
// A new draw for `tri` (its plane: `plane`; `rec`: its record, needed in a textured render only).
// The shade is the scene's emission index, or the back-face entry: no radiance is copied or
// compared per draw.
inline std::uint32_t raster_detail::rasterizer_impl::commit_record(float plane, const scene::triangle& tri,
                                                        const draw_record* rec, const frame& basis) {
  const std::uint32_t front = front_keys_[tri.index];
  const bool back = plane > 0.0f && (front & 1u);
  const auto draw = static_cast<std::uint32_t>(draw_keys_.size());
  const std::uint32_t key = back ? 1u : front >> 1;
  draw_keys_.push_back(key);
  draw_triangles_.push_back(tri.index);
  if (textured_) {
    draws_.push_back(*rec);
    draw_record& d = draws_.back();
    d.textured = !back;
    if (d.textured) {
      const glm::vec3 le1 = basis.to_local(tri.v1 - tri.v0), le2 = basis.to_local(tri.v2 - tri.v0);
      const float nn = glm::dot(rec->normal, rec->normal);
      d.grad_b1 = glm::cross(le2, rec->normal) / nn;
      d.grad_b2 = glm::cross(rec->normal, le1) / nn;
    }
  }
  return key_bits_ ? draw << key_bits_ | key : draw;
}

std::uint32_t raster_detail::rasterizer_impl::commit_draw(float plane, const scene::triangle& tri, const draw_record* rec,
                                                         const frame& basis) {
  return commit_record(plane, tri, rec, basis);
}

template <rasterizer_impl::mode M>
void raster_detail::rasterizer_impl::raster_face(int face, const glm::vec3 (&local)[3], draw_record& rec, std::uint32_t& draw,
                                      const frame& basis, const scene::triangle& tri) {
  const int n = n_;
  const float near = near_;

  // Clip in homogeneous coordinates.
  clip_vertex poly[max_clip_vertices + 1], tmp[max_clip_vertices + 1];
  int count = 3;
  unsigned all_out = 31, any_out = 0;
  for (int i = 0; i < 3; ++i) {
    poly[i] = to_clip(face, local[i]);
    // The five plane tests of clip_distance, written out (no switch in the loop).
    const clip_vertex& c = poly[i];
    const float gw = guard_band * c.w;
#if HEMILIGHT_RASTER_SSE2
    const unsigned code = clip_codes_sse2(c, gw, near);  // the same bits
#else
    const unsigned code = static_cast<unsigned>(c.w - near < 0.0f) | static_cast<unsigned>(gw - c.u < 0.0f) << 1 |
                          static_cast<unsigned>(gw + c.u < 0.0f) << 2 | static_cast<unsigned>(gw - c.v < 0.0f) << 3 |
                          static_cast<unsigned>(gw + c.v < 0.0f) << 4;
#endif
    all_out &= code;
    any_out |= code;
  }
  if (all_out) return;
  // With occlusion culling, a triangle hidden over what the face sees of it is not clipped.
  if (M == mode::depth && culling_ && any_out) {
    const clip_vertex c3[3] = {poly[0], poly[1], poly[2]};
    if (triangle_hidden(face, c3)) {
      ++stats_.face_triangles_occluded;
      return;
    }
  }
  if (any_out) ++stats_.clipped;
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
  // In double: coordinates up to 2^29 keep their 1/256-texel precision.
  const double scale = 0.5 * n * static_cast<double>(sub_one);
  const double v_offset = face == 0 ? 1.0 : 0.0;
  fixed_point fx[max_clip_vertices + 1];
  double ux[max_clip_vertices + 1], uy[max_clip_vertices + 1];  // unsnapped (edge coverage)
  for (int i = 0; i < count; ++i) {
    const double iw = 1.0 / static_cast<double>(poly[i].w);
    ux[i] = (poly[i].u * iw + 1.0) * scale;
    uy[i] = (poly[i].v * iw + v_offset) * scale;
    fx[i] = {round_to_int(ux[i]), round_to_int(uy[i])};
  }

  face_setup fs;
  // Fan of the clipped polygon.
  for (int i = 1; i + 1 < count; ++i) {
    const std::int64_t x[3] = {fx[0].x, fx[i].x, fx[i + 1].x}, y[3] = {fx[0].y, fx[i].y, fx[i + 1].y};
    const double exact[6] = {ux[0], ux[i], ux[i + 1], uy[0], uy[i], uy[i + 1]};
    draw_fixed<M>(face, x, y, fs, rec, draw, basis, tri, exact);
  }
}

// ---------------------------------------------------------------------------------------------
// draw_fixed: one triangle of the fixed-point grid on one face, as a chain of named steps
// ---------------------------------------------------------------------------------------------

namespace {

// Step 1 (set-up): the snapped vertices px, py ordered counter-clockwise into t.p, the unsnapped
// ones (exact: x0 x1 x2 y0 y1 y2 in px's order; null: the snapped ones) in the same order, and
// the bounds. Returns false for a triangle without area (it covers nothing).
inline bool set_up_fixed_triangle(const std::int64_t (&px)[3], const std::int64_t (&py)[3], const double* exact,
                                  fixed_triangle& t) noexcept {
  fixed_point* p = t.p;
  p[0] = {px[0], py[0]};
  p[1] = {px[1], py[1]};
  p[2] = {px[2], py[2]};
  const std::int64_t area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
  if (area == 0) return false;
  if (area < 0) std::swap(p[1], p[2]);
  if (exact) {
    const int order[3] = {0, area < 0 ? 2 : 1, area < 0 ? 1 : 2};
    for (int k = 0; k < 3; ++k) {
      t.unsnapped[k] = exact[order[k]];
      t.unsnapped[3 + k] = exact[3 + order[k]];
    }
  } else {
    for (int k = 0; k < 3; ++k) {
      t.unsnapped[k] = static_cast<double>(p[k].x);
      t.unsnapped[3 + k] = static_cast<double>(p[k].y);
    }
  }
  t.min_x = std::min({p[0].x, p[1].x, p[2].x});
  t.max_x = std::max({p[0].x, p[1].x, p[2].x});
  t.min_y = std::min({p[0].y, p[1].y, p[2].y});
  t.max_y = std::max({p[0].y, p[1].y, p[2].y});
  return true;
}

// Step 3 (box): the texels whose centre (k + 1/2) lies in t's bounds, clamped to a face of
// `columns` x `rows` texels.
inline texel_box centres_in_bounds(const fixed_triangle& t, int columns, int rows) noexcept {
  return {std::max<std::int64_t>(ceil_sub(t.min_x - sub_half), 0),
          std::min<std::int64_t>(floor_sub(t.max_x - sub_half), columns - 1),
          std::max<std::int64_t>(ceil_sub(t.min_y - sub_half), 0),
          std::min<std::int64_t>(floor_sub(t.max_y - sub_half), rows - 1)};
}

// The tie bias of edge (dx, dy): 0 for owned edges, 1 for the others (a texel centre is covered
// iff every edge function minus its bias is >= 0).
inline std::int64_t tie_bias(std::int64_t dx, std::int64_t dy) noexcept {
  return dy > 0 || (dy == 0 && dx < 0) ? 0 : 1;
}

// The visibility buffers of one face (offset to its first texel) and where the draw's fragments
// go: depth test into depth and ids, or counts (render_coverage; null in depth mode).
struct face_target {
  float* depth;
  std::uint32_t* ids;
  std::uint32_t* counts;
  tie_log* ties;  // where a fragment's depth equalled the one already there
};

// Writes the texels [lo, hi] of row y (the span paths): counts them in count mode, else the
// depth test of the draw's plane (fs) against `target`, on the fastest path allowed (avx2, simd;
// all bit-identical). Adds to `stats` (spans, fragments).
template <bool count_mode>
struct span_writer {
  face_target target;
  int n;                  // texels per row
  double z00, dzdy;       // the draw's depth plane (face_setup)
  float dzdx;
  std::uint32_t draw;     // the texel id written where the draw is nearer
  bool avx2, simd;
  raster_statistics& stats;

  void operator()(int y, int lo, int hi) const {
    ++stats.spans;
    stats.fragments += static_cast<std::size_t>(hi - lo + 1);
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(n);
    if (count_mode) {
      for (int x = lo; x <= hi; ++x) ++target.counts[row + static_cast<std::size_t>(x)];
      return;
    }
    const auto zrow = static_cast<float>(z00 + dzdy * y);
    float* drow = target.depth + row;
    std::uint32_t* irow = target.ids + row;
    int x = lo;
#if HEMILIGHT_RASTER_AVX2
    if (avx2) {
      span_avx2(drow, irow, lo, hi, zrow, dzdx, draw, target.ties);
      return;
    }
#endif
#if HEMILIGHT_RASTER_SSE2
    if (simd && hi - lo >= 3) x = span_sse2(drow, irow, x, hi, zrow, dzdx, draw, target.ties);
#endif
    // The scalar reference path (and the tail of the SIMD one).
    tie_log* const ties = target.ties;
    for (; x <= hi; ++x) {
      float z = zrow + dzdx * static_cast<float>(x);
      // 1/w is positive on the triangle; rounding near an edge-on plane may say otherwise, and a
      // covered texel must stay covered: clamp to the smallest positive depth (the farthest).
      z = z > FLT_MIN ? z : FLT_MIN;
      // Selects, not a branch: short spans would mispredict on every texel.
      const float old = drow[x];
      const bool closer = z > old;
      if (ties && z == old) ties->add(drow + x, &z, draw, 1u);
      drow[x] = closer ? z : old;
      irow[x] = closer ? draw : irow[x];
    }
  }
};

#if HEMILIGHT_RASTER_AVX2
// Step 4a (small-triangle kernel, AVX2): triangles up to avx2_extent across (the caller checks)
// are scanned over their box eight texels per step with 32-bit edge values, the coverage mask
// going straight into the depth test (or the counts). Cheaper than the span walk even for
// triangles that fill half their box. Reads p, box, the plane fs; writes target.
template <bool count_mode>
inline void scan_box_avx2(const fixed_point (&p)[3], const texel_box& box, int n, const face_target& target,
                          const face_setup& fs, std::uint32_t draw) noexcept {
  // The edge functions below, taken relative to the box's first texel centre (ox, oy): the
  // same integers, each below the bound derived at avx2_extent, so they fit 32 bits.
  const std::int64_t ox = box.x_begin * sub_one + sub_half, oy = box.y_begin * sub_one + sub_half;
  std::int32_t base[3], sx[3], sy[3];
  for (int k = 0; k < 3; ++k) {
    const fixed_point& a = p[k];
    const fixed_point& b = p[k == 2 ? 0 : k + 1];
    const std::int64_t dx = b.x - a.x, dy = b.y - a.y;
    sx[k] = static_cast<std::int32_t>(-dy * sub_one);
    sy[k] = static_cast<std::int32_t>(dx * sub_one);
    base[k] = static_cast<std::int32_t>(dx * (oy - a.y) - dy * (ox - a.x) - tie_bias(dx, dy));
  }
  small_triangle_avx2_impl<count_mode>(base, sx, sy, box.x_begin, box.x_end, box.y_begin, box.y_end, n, target.depth,
                                       target.ids, target.counts, fs.z00, fs.dzdy, fs.dzdx, draw, target.ties);
}
#endif

// Edge functions E(P) = d.x (P.y - A.y) - d.y (P.x - A.x) > 0 inside, d = B - A; at texel
// (x, y): E = ex x + ey y + e0. Ties (E = 0) belong to edges with d.y > 0, or d.y = 0 and
// d.x < 0: of two triangles sharing an edge exactly one owns it. e0 carries that bias, so a
// texel is covered iff ex x + ey y + e0 >= 0 for all three edges.
struct edge_functions {
  std::int64_t ex[3], ey[3], e0[3];
};

// Step 4 (edge set-up of the 64-bit paths): the edge functions of the counter-clockwise p.
inline edge_functions edge_functions_of(const fixed_point (&p)[3]) noexcept {
  edge_functions e;
  for (int k = 0; k < 3; ++k) {
    const fixed_point& a = p[k];
    const fixed_point& b = p[(k + 1) % 3];
    const std::int64_t dx = b.x - a.x, dy = b.y - a.y;
    e.ex[k] = -dy * sub_one;
    e.ey[k] = dx * sub_one;
    e.e0[k] = dx * (sub_half - a.y) - dy * (sub_half - a.x) - tie_bias(dx, dy);
  }
  return e;
}

// Step 4c (small-triangle kernel, scalar): a small box (most triangles of big scenes) is
// stepped texel by texel (additions only; a texel is in iff the OR of the three values is not
// negative), each row's run written at once by span (the triangle is convex: the run is
// contiguous).
template <class Span>
inline void scan_small_box(const edge_functions& e, const texel_box& box, Span& span) {
  std::int64_t row0 = e.ex[0] * box.x_begin + e.ey[0] * box.y_begin + e.e0[0];
  std::int64_t row1 = e.ex[1] * box.x_begin + e.ey[1] * box.y_begin + e.e0[1];
  std::int64_t row2 = e.ex[2] * box.x_begin + e.ey[2] * box.y_begin + e.e0[2];
  for (std::int64_t y = box.y_begin; y <= box.y_end; ++y, row0 += e.ey[0], row1 += e.ey[1], row2 += e.ey[2]) {
    std::int64_t a = row0, b = row1, c = row2;
    std::int64_t x = box.x_begin;
    while (x <= box.x_end && (a | b | c) < 0) {
      a += e.ex[0];
      b += e.ex[1];
      c += e.ex[2];
      ++x;
    }
    if (x > box.x_end) continue;
    const std::int64_t first = x;
    while (x <= box.x_end && (a | b | c) >= 0) {
      a += e.ex[0];
      b += e.ex[1];
      c += e.ex[2];
      ++x;
    }
    span(static_cast<int>(y), static_cast<int>(first), static_cast<int>(x - 1));
  }
}

// Step 5a (span walk: rows): the rows y_first..y_last the walk visits, from the box's rows. A
// horizontal edge (ex = 0) bounds the rows: ey y + e0 >= 0. A triangle reaching far past the
// face's sides (clipped triangles reach the guard band) has rows whose span lies wholly outside
// the face: they are walked for nothing. Its part inside the columns x_begin..x_end (widened by
// a texel) spans the rows whose centres lie within the y range of that part's vertices (the
// corners inside the strip and the edges' crossings of its sides); widened by a row, that range
// is conservative (the crossings are computed in double, to far below a texel), so the rows it
// drops have no covered texel and the walk stays exact. Convexity: the rows of the part are
// contiguous. Returns false when no row is left.
inline bool span_walk_rows(const fixed_triangle& t, const edge_functions& e, const texel_box& box, std::int64_t& y_first,
                           std::int64_t& y_last) noexcept {
  y_first = box.y_begin;
  y_last = box.y_end;
  for (int k = 0; k < 3; ++k) {
    if (e.ex[k] != 0) continue;
    if (e.ey[k] > 0) {
      y_first = std::max(y_first, -floor_div(e.e0[k], e.ey[k]));  // ceil(-e0 / ey)
    } else if (e.ey[k] < 0) {
      y_last = std::min(y_last, floor_div(e.e0[k], -e.ey[k]));
    } else if (e.e0[k] < 0) {
      return false;  // a zero-length edge (not reached: such triangles have no area)
    }
  }
  const fixed_point* p = t.p;
  const double strip_lo = static_cast<double>((box.x_begin - 1) * sub_one + sub_half);
  const double strip_hi = static_cast<double>((box.x_end + 1) * sub_one + sub_half);
  if (static_cast<double>(t.min_x) < strip_lo || static_cast<double>(t.max_x) > strip_hi) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int k = 0; k < 3; ++k) {
      const double ax = static_cast<double>(p[k].x), ay = static_cast<double>(p[k].y);
      const double bx = static_cast<double>(p[(k + 1) % 3].x), by = static_cast<double>(p[(k + 1) % 3].y);
      if (ax >= strip_lo && ax <= strip_hi) {
        lo = std::min(lo, ay);
        hi = std::max(hi, ay);
      }
      for (const double side : {strip_lo, strip_hi}) {
        if ((ax < side) == (bx < side)) continue;
        const double y = ay + (side - ax) / (bx - ax) * (by - ay);
        lo = std::min(lo, y);
        hi = std::max(hi, y);
      }
    }
    if (!(lo <= hi)) return false;  // the triangle passes beside the face's columns
    // Rows k with centre k + 1/2 in [lo, hi] (fixed point), one more on each side.
    y_first = std::max(y_first, static_cast<std::int64_t>(std::floor((lo - sub_half) / sub_one)));
    y_last = std::min(y_last, static_cast<std::int64_t>(std::ceil((hi - sub_half) / sub_one)));
  }
  return y_first <= y_last;
}

// Step 5b (span walk: edges): the exact incremental bounds of row y_first. Edge k bounds x from
// the left when ex > 0: x >= L(y) = ceil(-(ey y + e0) / ex), from the right when ex < 0:
// x <= R(y) = floor((ey y + e0) / -ex). Both are kept as quotient + remainder and stepped per
// row with additions only (a Bresenham-style exact walk, walk_rows). Writes nl left and nr
// right walks.
inline void set_up_edge_walks(const edge_functions& e, std::int64_t y_first, edge_walk (&left)[3], int& nl,
                              edge_walk (&right)[3], int& nr) noexcept {
  nl = 0;
  nr = 0;
  for (int k = 0; k < 3; ++k) {
    const std::int64_t r = e.ey[k] * y_first + e.e0[k];
    if (e.ex[k] > 0) {
      edge_walk& w = left[nl++];
      w.m = e.ex[k];
      const std::int64_t num = -r;                       // L = ceil(num / m), rem = L m - num
      w.bound = -floor_div(-num, w.m);
      w.rem = w.bound * w.m - num;
      const std::int64_t d = -e.ey[k];                   // num steps by d per row
      w.q_step = floor_div(d, w.m);
      w.r_step = d - w.q_step * w.m;
    } else if (e.ex[k] < 0) {
      edge_walk& w = right[nr++];
      w.m = -e.ex[k];
      w.bound = floor_div(r, w.m);                       // R = floor(r / m), rem = r - R m
      w.rem = r - w.bound * w.m;
      w.q_step = floor_div(e.ey[k], w.m);                // r steps by ey per row
      w.r_step = e.ey[k] - w.q_step * w.m;
    }
  }
  assert((nl == 1 && nr == 1) || (nl == 1 && nr == 2) || (nl == 2 && nr == 1));
}

}  // namespace

// Step 2 (edge coverage hook): the hard texels (those a hard edge may cross) that t's box
// overlaps get the triangle's exact share (edge_texels), committing the draw if needed; the
// coverage paths then draw it as without the option. Returns false when the box misses the
// face (nothing to draw at all). Inlined into draw_fixed (its only caller): out of line, t would
// have to be stored for every triangle drawn.
#if defined(__GNUC__) || defined(__clang__)
__attribute__((always_inline))
#endif
inline bool raster_detail::rasterizer_impl::draw_hard_texels(int face, const fixed_triangle& t, face_setup& fs,
                                                      draw_record& rec, std::uint32_t& draw, const frame& basis,
                                                      const scene::triangle& tri) {
  const int rows = face == 0 ? n_ : n_ / 2;
  // Texels the box overlaps (not only those whose centre it holds; grown by the snapping for
  // the unsnapped triangle), clamped to the face.
  const std::int64_t c0 = std::max<std::int64_t>(floor_sub(t.min_x - 1), 0);
  const std::int64_t c1 = std::min<std::int64_t>(ceil_sub(t.max_x + 1) - 1, n_ - 1);
  const std::int64_t r0 = std::max<std::int64_t>(floor_sub(t.min_y - 1), 0);
  const std::int64_t r1 = std::min<std::int64_t>(ceil_sub(t.max_y + 1) - 1, rows - 1);
  if (c0 > c1 || r0 > r1) return false;
  if (edge_box_is_hard(face, c0, c1, r0, r1)) {
    if (draw == 0) draw = commit_record(rec.plane, tri, &rec, basis);
    fs.prepare(face, texel_step_, first_centre_, rec);
    const std::int64_t qx[3] = {t.p[0].x, t.p[1].x, t.p[2].x}, qy[3] = {t.p[0].y, t.p[1].y, t.p[2].y};
    edge_texels(face, qx, qy, t.unsnapped, fs, draw, rec.plane > 0.0f);
  }
  return true;
}

template <rasterizer_impl::mode M>
void raster_detail::rasterizer_impl::draw_fixed(int face, const std::int64_t (&px)[3], const std::int64_t (&py)[3],
                                                face_setup& fs, draw_record& rec, std::uint32_t& draw,
                                                const frame& basis, const scene::triangle& tri, const double* exact) {
  const int n = n_;
  const int rows = face == 0 ? n : n / 2;
  // 1. Set-up: counter-clockwise vertices and bounds.
  fixed_triangle t;
  if (!set_up_fixed_triangle(px, py, exact, t)) return;
  // 2. Exact edge coverage of the hard texels the triangle touches.
  if (M == mode::depth && edge_ && (edges_.hard_faces >> face & 1u))
    if (!draw_hard_texels(face, t, fs, rec, draw, basis, tri)) return;
  // 3. The box of texel centres; the draw and its depth plane once it covers one.
  const texel_box box = centres_in_bounds(t, n, rows);
  if (box.x_begin > box.x_end || box.y_begin > box.y_end) return;
  fs.prepare(face, texel_step_, first_centre_, rec);
  // 3b. With occlusion culling, a big or clipped triangle hidden over its whole box is dropped.
  if (M == mode::depth && culling_ && plane_hidden(face, box, fs)) {
    ++stats_.face_triangles_occluded;
    return;
  }
  if (draw == 0) draw = commit_record(rec.plane, tri, &rec, basis);
  const std::size_t face_offset = hemicube_face_offset(n, static_cast<hemicube_face>(face));
  const face_target target{depth_.data() + face_offset, ids_.data() + face_offset,
                           M == mode::count ? counts_->data() + face_offset : nullptr, tie_sink_};

  // 4. Small-triangle kernels: the box scanned without spans.
#if HEMILIGHT_RASTER_AVX2
  if (avx2_ && t.max_x - t.min_x <= avx2_extent && t.max_y - t.min_y <= avx2_extent) {
    scan_box_avx2<M == mode::count>(t.p, box, n, target, fs, draw);
    return;
  }
#endif
  const edge_functions e = edge_functions_of(t.p);
#if HEMILIGHT_RASTER_SSE2
  if (simd_ && t.max_x - t.min_x <= simd_extent && t.max_y - t.min_y <= simd_extent) {
    // Small triangle, SSE2: edge functions relative to the box's first texel fit in 32 bits
    // (extent <= 32 texels: |E| < 2^29), so four texels are tested per step with 32-bit
    // additions, and the coverage mask goes straight into the depth test: no span search,
    // no branch per texel. Same coverage (exact integers) and depths as the scalar path.
    small_triangle_sse2_impl<M == mode::count>(e.ex, e.ey, e.e0, box.x_begin, box.x_end, box.y_begin, box.y_end, n,
                                               target.depth, target.ids, target.counts, fs.z00, fs.dzdy, fs.dzdx, draw,
                                               tie_sink_);
    return;
  }
#endif
  span_writer<M == mode::count> span{target, n, fs.z00, fs.dzdy, fs.dzdx, draw, avx2_, simd_, stats_};
  if (box.x_end - box.x_begin < 24 && (box.x_end - box.x_begin + 1) * (box.y_end - box.y_begin + 1) <= 96) {
    scan_small_box(e, box, span);
    return;
  }

  // 5. The exact span walk: its rows, its edges, then row by row.
  std::int64_t y_first, y_last;
  if (!span_walk_rows(t, e, box, y_first, y_last)) return;
  edge_walk left[3], right[3];
  int nl, nr;
  set_up_edge_walks(e, y_first, left, nl, right, nr);
#if HEMILIGHT_RASTER_AVX2
  if (M == mode::depth && avx2_) {
    walk_depth_avx2(nl, nr, left, right, y_first, y_last, box.x_begin, box.x_end, target.depth, target.ids, n, fs.z00,
                    fs.dzdy, fs.dzdx, draw, stats_, tie_sink_);
    return;
  }
#endif
  walk_rows_of(nl, nr, left, right, y_first, y_last, box.x_begin, box.x_end, span);
}

void raster_detail::rasterizer_impl::resolve_textured(std::size_t count, const float* distance, const std::uint32_t* ids,
                                                      const radiance_texture& texture, float* red, float* green,
                                                      float* blue) const {
  for (std::size_t i = 0; i < count; ++i) {
    const draw_record& rec = draws_[ids[i] >> key_bits_];
    if (!rec.textured) continue;
    const glm::vec3 l = textured_texel(rec, i, distance[i], texture);
    red[i] = l.x;
    green[i] = l.y;
    blue[i] = l.z;
  }
}

void raster_detail::rasterizer_impl::render(const glm::vec3& position, const frame& basis, int resolution, hemicube_buffer& out,
                                 const radiance_texture* texture) {
  const char* who = "hemicube_rasterizer::render";
  check_arguments(who, position, basis, resolution);
  if (texture) texture->validate(who);
  prepare(resolution);
  textured_ = texture && scene_->has_lightmap_uvs();
  texture_ = textured_ ? texture : nullptr;
  if (edge_) edge_mark_hard(position, basis);
  draw_all<mode::depth>(position, basis);
  const bool see_through = !scene_->see_through_triangles().empty();
  if (see_through) draw_see_through(position, basis);

  // Resolve. Distance along the unit centre direction d = D / |D| (D = a + u c + v r): the hit
  // point is D / (1/w), so t = |D| / (1/w); a miss has 1/w = 0 and gets +inf. 1/w is the
  // triangle's exact plane evaluated at the texel centre, so this is the ray-plane intersection.
  out.resize(resolution);
  out.position = position;
  out.basis = basis;
  const std::size_t count = hemicube_texel_count(resolution);
  float* depth = depth_.data();
  const float* lengths = lengths_.data();
  std::uint32_t* ids = ids_.data();
  const shade* shades = shades_.data();
  const std::uint32_t* keys = draw_keys_.data();
  float* distance = out.distance.data();
  float* red = out.channel(0);
  float* green = out.channel(1);
  float* blue = out.channel(2);
  std::uint8_t* flags = out.flags.data();
#if HEMILIGHT_RASTER_AVX2
  if (avx2_) {
    if (key_bits_)
      resolve_texels_avx2<true>(count, depth, lengths, ids, shades, keys, key_bits_, distance, red, green, blue, flags);
    else
      resolve_texels_avx2<false>(count, depth, lengths, ids, shades, keys, 0, distance, red, green, blue, flags);
    const std::size_t done = count - count % 8, rest = count - done;
    resolve_texels(rest, depth + done, lengths + done, ids + done, shades, {keys, key_bits_}, distance + done,
                   red + done, green + done, blue + done, flags + done, false);
  } else
#endif
    resolve_texels(count, depth, lengths, ids, shades, {keys, key_bits_}, distance, red, green, blue, flags, simd_);
  depth_clear_ = true;  // every path of the resolve zeroed the depths it read (the padding stays 0)
  if (sky_) {
    // Misses see the environment along the texel's world direction.
    for (std::size_t i = 0; i < count; ++i) {
      if (!(flags[i] & texel_miss)) continue;
      const glm::vec4 l = sky_->sample(basis.to_world(directions_[i]));
      red[i] = l.x;
      green[i] = l.y;
      blue[i] = l.z;
    }
  }
  if (textured_) resolve_textured(count, distance, ids, *texture, red, green, blue);
  if (edge_) {
    // A texel an alpha-tested triangle wins keeps what its centre sees (no partial coverage).
    if (see_through) keep_cutouts(out);
    edge_group_fragments();
    edge_blend(out, basis, textured_ ? texture : nullptr);
    if (see_through) restore_cutouts(out);
  }
  if (see_through) composite_translucent(out, textured_ ? texture : nullptr);
}

void raster_detail::rasterizer_impl::render_coverage(const glm::vec3& position, const frame& basis, int resolution,
                                          std::vector<std::uint32_t>& counts) {
  check_arguments("hemicube_rasterizer::render_coverage", position, basis, resolution);
  prepare(resolution);
  // Padded while drawing like the visibility buffers (the AVX2 kernel stores back past the end).
  counts.assign(hemicube_texel_count(resolution) + 8, 0u);
  counts_ = &counts;
  textured_ = false;
  texture_ = nullptr;
  draw_all<mode::count>(position, basis);
  counts_ = nullptr;
  counts.resize(hemicube_texel_count(resolution));
  std::fill(ids_.begin(), ids_.end(), 0u);  // seen_triangle() after this: no_triangle everywhere
}

}  // namespace hemilight
