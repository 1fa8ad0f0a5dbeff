// The lightmap baker (bake.hpp): exact UV coverage, sample placement, cache passes with bounces,
// dilation.
#include "hemilight/bake.hpp"

#include "hemilight/geometry.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/rays.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <type_traits>
#include <string>

namespace hemilight {

namespace {

constexpr float pi_f = 3.14159265358979323846f;

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Twice the signed area of (a, b, c) in double.
double cross2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

void check_size(const char* who, int width, int height) {
  if (width < 1 || width > max_lightmap_size || height < 1 || height > max_lightmap_size)
    throw_invalid_argument(std::string(who) + ": lightmap size " + std::to_string(width) + " x " + std::to_string(height) +
                           " is invalid: width and height must be in [1, " + std::to_string(max_lightmap_size) + "]");
}

// Validates what compute_lightmap_samples reads (scene::create checks the rest later).
void check_input(const char* who, const bake_input& in, bool uvs_in_unit_square = true) {
  const scene_desc& d = in.scene;
  if (d.triangle_count > 0 && !d.indices) throw_invalid_argument(std::string(who) + ": indices is null");
  if (d.vertex_count > 0 && !d.positions) throw_invalid_argument(std::string(who) + ": positions is null");
  if (!d.lightmap_uvs)
    throw_invalid_argument(std::string(who) + ": the scene has no lightmap UVs (scene_desc::lightmap_uvs is null)");
  // Albedo above 1 would make the bounces diverge (scene::create only rejects negative values).
  if (d.materials)
    for (std::size_t i = 0; i < d.triangle_count; ++i)
      for (int c = 0; c < 3; ++c)
        if (!(d.materials[i].albedo[c] >= 0.0f && d.materials[i].albedo[c] <= 1.0f))
          throw_invalid_argument(std::string(who) + ": materials[" + std::to_string(i) + "].albedo = " +
                                 num(d.materials[i].albedo[c]) + " is outside [0, 1]");
  for (std::size_t i = 0; i < 3 * d.triangle_count; ++i)
    if (d.indices[i] >= d.vertex_count)
      throw_invalid_argument(std::string(who) + ": indices[" + std::to_string(i) + "] = " + std::to_string(d.indices[i]) +
                             " is out of range: " + std::to_string(d.vertex_count) + " vertices");
  for (std::size_t i = 0; i < d.vertex_count; ++i) {
    const glm::vec2 uv = d.lightmap_uvs[i];
    for (int c = 0; c < 2; ++c)
      if (uvs_in_unit_square ? !(uv[c] >= 0.0f && uv[c] <= 1.0f) : !std::isfinite(uv[c]))
        throw_invalid_argument(std::string(who) + ": lightmap_uvs[" + std::to_string(i) + "]." + (c ? "v" : "u") + " = " +
                               num(uv[c]) + (uvs_in_unit_square ? " is outside [0, 1]" : " is not finite"));
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(d.positions[i][c]))
        throw_invalid_argument(std::string(who) + ": positions[" + std::to_string(i) + "] is not finite");
    if (in.normals)
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(in.normals[i][c]))
          throw_invalid_argument(std::string(who) + ": normals[" + std::to_string(i) + "] is not finite");
  }
}

// Per-triangle data in double: UVs in texel units, 3D vertices, areas.
struct tri_data {
  glm::dvec2 t[3];      // texel units
  double uv_area = 0;   // texel units, absolute
  double area3 = 0;     // scene units^2
  bool drawn = false;   // nonzero 3D area
};

tri_data make_tri(const scene_desc& d, std::size_t i, int w, int h) {
  tri_data r;
  const std::uint32_t* idx = d.indices + 3 * i;
  for (int k = 0; k < 3; ++k) {
    const glm::vec2 uv = d.lightmap_uvs[idx[k]];
    r.t[k] = glm::dvec2(double(uv.x) * w, double(uv.y) * h);
  }
  r.uv_area = 0.5 * std::fabs(cross2(r.t[0], r.t[1], r.t[2]));
  const glm::dvec3 p0(d.positions[idx[0]]), p1(d.positions[idx[1]]), p2(d.positions[idx[2]]);
  r.area3 = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
  r.drawn = r.area3 > 0.0;
  return r;
}

// Barycentrics of q in the 2D triangle t (b1, b2 of vertices 1 and 2); false if degenerate.
bool barycentric(const glm::dvec2 (&t)[3], const glm::dvec2& q, double& b1, double& b2) {
  const double det = cross2(t[0], t[1], t[2]);
  if (det == 0.0) return false;
  b1 = cross2(t[0], q, t[2]) / det;
  b2 = cross2(t[0], t[1], q) / det;
  return true;
}

struct clip_d {
  double area = 0;
  glm::dvec2 centroid{0.0};
};

// Sutherland-Hodgman of a triangle against the texel square, area and centroid (double).
clip_d clip_texel(const glm::dvec2 (&tri)[3], int x, int y) {
  glm::dvec2 a[9], b[9];
  int n = 3;
  for (int k = 0; k < 3; ++k) a[k] = tri[k];
  const double lo[2] = {double(x), double(y)}, hi[2] = {double(x) + 1.0, double(y) + 1.0};
  for (int plane = 0; plane < 4 && n > 0; ++plane) {
    const int axis = plane & 1;
    const bool upper = plane >= 2;
    const double bound = upper ? hi[axis] : lo[axis];
    // Signed distance inside the half-plane (>= 0 inside).
    const auto inside = [&](const glm::dvec2& p) { return upper ? bound - p[axis] : p[axis] - bound; };
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const glm::dvec2& p = a[i];
      const glm::dvec2& q = a[(i + 1) % n];
      const double dp = inside(p), dq = inside(q);
      if (dp >= 0.0) b[m++] = p;
      if ((dp >= 0.0) != (dq >= 0.0)) {
        const double s = dp / (dp - dq);
        glm::dvec2 r = p + s * (q - p);
        r[axis] = bound;  // exactly on the boundary
        b[m++] = r;
      }
    }
    n = m;
    std::copy(b, b + m, a);
  }
  clip_d r;
  if (n < 3) return r;
  double area2 = 0.0;
  glm::dvec2 c(0.0);
  const glm::dvec2 o = a[0];  // relative to the first vertex: better conditioned
  for (int i = 1; i + 1 < n; ++i) {
    const double w = cross2(o, a[i], a[i + 1]);
    area2 += w;
    c += w * (o + a[i] + a[i + 1]) / 3.0;
  }
  if (area2 == 0.0) return r;
  r.area = std::fabs(area2) * 0.5;
  r.centroid = c / area2;
  return r;
}

// Texel bounding box of a triangle in texel units, clamped to the lightmap.
void texel_bounds(const tri_data& t, int w, int h, int& x0, int& y0, int& x1, int& y1) {
  const double minx = std::min({t.t[0].x, t.t[1].x, t.t[2].x}), maxx = std::max({t.t[0].x, t.t[1].x, t.t[2].x});
  const double miny = std::min({t.t[0].y, t.t[1].y, t.t[2].y}), maxy = std::max({t.t[0].y, t.t[1].y, t.t[2].y});
  x0 = std::clamp(int(std::floor(minx)), 0, w - 1);
  y0 = std::clamp(int(std::floor(miny)), 0, h - 1);
  x1 = std::clamp(int(std::ceil(maxx)) - 1, 0, w - 1);
  y1 = std::clamp(int(std::ceil(maxy)) - 1, 0, h - 1);
}

// Calls f(x, y, k) for every texel of the lightmap in the bounding box of a drawn triangle.
template <class F>
void for_each_texel_in_bounds(const tri_data& t, int w, int h, F&& f) {
  if (!t.drawn) return;
  int x0, y0, x1, y1;
  texel_bounds(t, w, h, x0, y0, x1, y1);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) f(x, y, std::size_t(y) * std::size_t(w) + std::size_t(x));
}

void check_options(const bake_options& o, const char* who = "bake_lightmap", bool size = true) {
  if (size) check_size(who, o.width, o.height);
  if (!is_valid_hemicube_resolution(o.resolution))
    throw_invalid_argument(std::string(who) + ": resolution " + std::to_string(o.resolution) +
                           " is invalid: it must be even and in [2, 4096]");
  if (o.bounces < 1 || o.bounces > 64)
    throw_invalid_argument(std::string(who) + ": bounces " + std::to_string(o.bounces) + " is not in [1, 64]");
  if (!(o.min_coverage >= 0.0f && o.min_coverage <= 1.0f))
    throw_invalid_argument(std::string(who) + ": min_coverage " + num(o.min_coverage) + " is not in [0, 1]");
  if (!(o.offset_texels >= 0.0f) || !std::isfinite(o.offset_texels))
    throw_invalid_argument(std::string(who) + ": offset_texels " + num(o.offset_texels) + " must be finite and >= 0");
  if (o.dilation < -1)
    throw_invalid_argument(std::string(who) + ": dilation " + std::to_string(o.dilation) + " must be >= -1");
  if (o.thread_count < 0)
    throw_invalid_argument(std::string(who) + ": thread_count " + std::to_string(o.thread_count) + " must be >= 0");
  validate_cache_options(o.cache, std::string(who) + ": cache");  // whatever use_cache says
  try {
    validate_lights(o.lights.data(), o.lights.size());
    validate_direct_options(o.direct);
  } catch (const error& e) {
    throw_invalid_argument(std::string(who) + ": " + e.what());
  }
  for (std::size_t c = 0; c < o.shadow_mask_lights.size(); ++c) {
    const int l = o.shadow_mask_lights[c];
    if (l < -1 || (l >= 0 && std::size_t(l) >= o.lights.size()))
      throw_invalid_argument(std::string(who) + ": shadow_mask_lights[" + std::to_string(c) + "] = " + std::to_string(l) +
                             " is not -1 or a light index (there are " + std::to_string(o.lights.size()) + " lights)");
  }
}

}  // namespace

texel_clip clip_triangle_to_texel(const glm::vec2& a, const glm::vec2& b, const glm::vec2& c, int x, int y) noexcept {
  const glm::dvec2 t[3] = {glm::dvec2(a), glm::dvec2(b), glm::dvec2(c)};
  const clip_d r = clip_texel(t, x, y);
  texel_clip out;
  out.area = float(r.area);
  out.centroid = r.area > 0.0 ? glm::vec2(r.centroid) : glm::vec2(float(x) + 0.5f, float(y) + 0.5f);
  return out;
}

frame lightmap_tangent_frame(const glm::vec3 (&p)[3], const glm::vec2 (&uv)[3], const glm::vec3& n) noexcept {
  const glm::dvec3 e1 = glm::dvec3(p[1]) - glm::dvec3(p[0]), e2 = glm::dvec3(p[2]) - glm::dvec3(p[0]);
  const glm::dvec2 d1 = glm::dvec2(uv[1]) - glm::dvec2(uv[0]), d2 = glm::dvec2(uv[2]) - glm::dvec2(uv[0]);
  const double det = d1.x * d2.y - d2.x * d1.y;
  const glm::dvec3 nd(n);
  frame f = make_frame(n);
  if (!(std::fabs(det) > 0.0) || !std::isfinite(det)) return f;
  const glm::dvec3 dpdu = (e1 * d2.y - e2 * d1.y) / det, dpdv = (e2 * d1.x - e1 * d2.x) / det;
  // Projections onto the tangent plane; "nearly along n" = less than 1e-6 of the length left.
  const glm::dvec3 tu = dpdu - nd * glm::dot(nd, dpdu), tv = dpdv - nd * glm::dot(nd, dpdv);
  const double lu = glm::length(tu), lv = glm::length(tv);
  glm::dvec3 t, b;
  if (lu > 1e-6 * glm::length(dpdu) && lu > 0.0) {
    t = tu / lu;
    b = glm::cross(nd, t);
    if (glm::dot(b, dpdv) < 0.0) b = -b;
  } else if (lv > 1e-6 * glm::length(dpdv) && lv > 0.0) {
    b = tv / lv;
    t = glm::cross(b, nd);  // right-handed: the sign of u is unknown when dP/du is along n
  } else {
    return f;
  }
  f.t = glm::vec3(t);
  f.b = glm::vec3(b);
  return f;
}

std::vector<std::string> write_bake_exrs(const bake_result& r, const std::string& prefix, exr_pixel_type type) {
  std::vector<std::string> written;
  const auto put = [&](const std::string& suffix, const image& img) {
    write_exr(prefix + suffix, img, type);
    written.push_back(prefix + suffix);
  };
  put("_irradiance.exr", r.irradiance);
  put("_mask.exr", bake_mask_image(r));
  for (std::size_t k = 0; k < r.sh_l1.size(); ++k)
    if (r.sh_l1[k].width > 0) put("_sh_l1_" + std::to_string(k) + ".exr", r.sh_l1[k]);
  for (std::size_t k = 0; k < r.hl2.size(); ++k)
    if (r.hl2[k].width > 0) put("_hl2_" + std::to_string(k) + ".exr", r.hl2[k]);
  if (r.shadow_mask.width > 0) put("_shadow_mask.exr", r.shadow_mask);
  return written;
}

namespace {

// Step 1 for the covered texels only (the baker's own form of lightmap_samples): one entry per
// texel with coverage > 0, in texel order, each field as lightmap_samples defines it. Memory: a
// 4-byte slot per texel while it is computed, then about 80 bytes per covered texel.
struct sparse_samples {
  int width = 0, height = 0;
  std::vector<std::size_t> texel;  // texel index (row-major), increasing
  std::vector<float> coverage;
  std::vector<std::uint32_t> owner, sample_triangle;
  std::vector<glm::vec2> centroid;
  std::vector<glm::vec3> position, normal, tangent, bitangent;
  std::vector<float> texel_world_size;
  std::size_t overlapping_texels = 0;

  std::size_t size() const { return texel.size(); }
};

sparse_samples compute_sparse_samples(const bake_input& input, int width, int height) {
  const char* who = "compute_lightmap_samples";
  check_size(who, width, height);
  check_input(who, input);
  const scene_desc& d = input.scene;
  const std::size_t texels = std::size_t(width) * std::size_t(height);
  constexpr std::uint32_t none = lightmap_samples::no_triangle;

  std::vector<tri_data> tris(d.triangle_count);
  for (std::size_t i = 0; i < d.triangle_count; ++i) {
    tris[i] = make_tri(d, i, width, height);
    // A triangle with 3D area but (next to) no UV area would get no texels: a broken unwrap.
    if (tris[i].drawn && !(tris[i].uv_area > 1e-12 * double(width) * double(height)))
      throw_invalid_argument(std::string(who) + ": triangle " + std::to_string(i) +
                             " has zero area in lightmap UV space (but not in 3D): it would get no texels");
  }

  // Pass A: coverage sum, area-weighted centroid, owner (largest area, ties to the lower index:
  // triangles are visited in index order and only a strictly larger area replaces the owner).
  // Per covered texel: a slot, made when a triangle first covers it (the sums per texel are
  // formed in triangle order whatever the slot).
  constexpr std::uint32_t no_slot = 0xffffffffu;
  std::vector<std::uint32_t> slot_of(texels, no_slot);
  std::vector<std::size_t> slot_texel;
  std::vector<double> sum_area, owner_area;
  std::vector<glm::dvec2> sum_centroid, owner_centroid;
  std::vector<std::uint32_t> owner;
  for (std::size_t i = 0; i < d.triangle_count; ++i)
    for_each_texel_in_bounds(tris[i], width, height, [&](int x, int y, std::size_t k) {
      const clip_d c = clip_texel(tris[i].t, x, y);
      if (!(c.area > 0.0)) return;
      std::uint32_t q = slot_of[k];
      if (q == no_slot) {
        if (slot_texel.size() >= std::size_t(no_slot))
          throw error(status::out_of_memory, std::string(who) + ": more than 2^32 - 1 covered texels");
        q = slot_of[k] = std::uint32_t(slot_texel.size());
        slot_texel.push_back(k);
        sum_area.push_back(0.0);
        owner_area.push_back(0.0);
        sum_centroid.emplace_back(0.0);
        owner_centroid.emplace_back(0.0);
        owner.push_back(none);
      }
      sum_area[q] += c.area;
      sum_centroid[q] += c.area * c.centroid;
      if (c.area > owner_area[q]) {
        owner_area[q] = c.area;
        owner[q] = std::uint32_t(i);
        owner_centroid[q] = c.centroid;
      }
    });
  // Slots in texel order (the order of the samples downstream), and the map to them.
  const std::size_t count = slot_texel.size();
  std::vector<std::uint32_t> order(count);
  for (std::size_t q = 0; q < count; ++q) order[q] = std::uint32_t(q);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return slot_texel[a] < slot_texel[b]; });
  const auto permute = [&](auto& v) {
    std::remove_reference_t<decltype(v)> out(count);
    for (std::size_t n = 0; n < count; ++n) out[n] = v[order[n]];
    v = std::move(out);
  };
  permute(slot_texel);
  permute(sum_area);
  permute(owner_area);
  permute(sum_centroid);
  permute(owner_centroid);
  permute(owner);
  for (std::size_t n = 0; n < count; ++n) slot_of[slot_texel[n]] = std::uint32_t(n);
  std::vector<glm::dvec2> centroid(count);
  for (std::size_t n = 0; n < count; ++n) centroid[n] = sum_centroid[n] / sum_area[n];
  std::vector<glm::dvec2>().swap(sum_centroid);

  // Pass B: the triangle the combined centroid is mapped through: the owner if it contains it,
  // else the covering triangle with the largest area that contains it (ties: lower index).
  const double eps = 1e-9;
  std::vector<std::uint32_t> through(count, none);
  std::vector<double> through_area(count, 0.0);
  for (std::size_t i = 0; i < d.triangle_count; ++i)
    for_each_texel_in_bounds(tris[i], width, height, [&](int x, int y, std::size_t k) {
      const std::uint32_t q = slot_of[k];
      if (q == no_slot || through[q] == owner[q]) return;
      double b1, b2;
      if (!barycentric(tris[i].t, centroid[q], b1, b2) || b1 < -eps || b2 < -eps || b1 + b2 > 1.0 + eps) return;
      const clip_d c = clip_texel(tris[i].t, x, y);
      if (!(c.area > 0.0)) return;
      if (std::uint32_t(i) == owner[q] || through[q] == none || c.area > through_area[q]) {
        through[q] = std::uint32_t(i);
        through_area[q] = c.area;
      }
    });
  std::vector<std::uint32_t>().swap(slot_of);

  sparse_samples s;
  s.width = width;
  s.height = height;
  s.texel = std::move(slot_texel);
  s.coverage.resize(count);
  s.owner = std::move(owner);
  s.sample_triangle.resize(count);
  s.centroid.resize(count);
  s.position.resize(count);
  s.normal.resize(count);
  s.texel_world_size.resize(count);
  s.tangent.resize(count);
  s.bitangent.resize(count);
  for (std::size_t n = 0; n < count; ++n) {
    s.coverage[n] = float(std::min(1.0, sum_area[n]));
    if (sum_area[n] > 1.001) ++s.overlapping_texels;
    std::uint32_t ti = through[n];
    glm::dvec2 q = centroid[n];
    if (ti == none) {  // the combined centroid lies on no covering triangle: the owner's own centroid
      ti = s.owner[n];
      q = owner_centroid[n];
    }
    const tri_data& t = tris[ti];
    double b1 = 0, b2 = 0;
    barycentric(t.t, q, b1, b2);
    // Clamp to the triangle (the point is inside up to rounding).
    b1 = std::clamp(b1, 0.0, 1.0);
    b2 = std::clamp(b2, 0.0, 1.0 - b1);
    const double b0 = 1.0 - b1 - b2;
    const std::uint32_t* idx = d.indices + 3 * std::size_t(ti);
    const glm::dvec3 p0(d.positions[idx[0]]), p1(d.positions[idx[1]]), p2(d.positions[idx[2]]);
    const glm::dvec3 face = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    glm::dvec3 nrm = face;
    if (input.normals) {
      const glm::dvec3 ni =
          b0 * glm::dvec3(input.normals[idx[0]]) + b1 * glm::dvec3(input.normals[idx[1]]) + b2 * glm::dvec3(input.normals[idx[2]]);
      const double len = glm::length(ni);
      if (len > 1e-6) nrm = ni / len;
    }
    s.sample_triangle[n] = ti;
    s.centroid[n] = glm::vec2(float(q.x / width), float(q.y / height));
    s.position[n] = glm::vec3(b0 * p0 + b1 * p1 + b2 * p2);
    s.normal[n] = glm::vec3(nrm);
    s.texel_world_size[n] = float(std::sqrt(t.area3 / t.uv_area));
    const glm::vec3 tp[3] = {d.positions[idx[0]], d.positions[idx[1]], d.positions[idx[2]]};
    const glm::vec2 tuv[3] = {d.lightmap_uvs[idx[0]], d.lightmap_uvs[idx[1]], d.lightmap_uvs[idx[2]]};
    const frame f = lightmap_tangent_frame(tp, tuv, s.normal[n]);
    s.tangent[n] = f.t;
    s.bitangent[n] = f.b;
  }
  return s;
}

}  // namespace

lightmap_samples compute_lightmap_samples(const bake_input& input, int width, int height) {
  const sparse_samples sp = compute_sparse_samples(input, width, height);
  const std::size_t texels = std::size_t(width) * std::size_t(height);
  constexpr std::uint32_t none = lightmap_samples::no_triangle;
  lightmap_samples s;
  s.width = width;
  s.height = height;
  s.coverage.assign(texels, 0.0f);
  s.owner.assign(texels, none);
  s.sample_triangle.assign(texels, none);
  s.centroid.assign(texels, glm::vec2(0.0f));
  s.position.assign(texels, glm::vec3(0.0f));
  s.normal.assign(texels, glm::vec3(0.0f, 0.0f, 1.0f));
  s.texel_world_size.assign(texels, 0.0f);
  s.tangent.assign(texels, glm::vec3(1.0f, 0.0f, 0.0f));
  s.bitangent.assign(texels, glm::vec3(0.0f, 1.0f, 0.0f));
  s.overlapping_texels = sp.overlapping_texels;
  for (std::size_t n = 0; n < sp.size(); ++n) {
    const std::size_t k = sp.texel[n];
    s.coverage[k] = sp.coverage[n];
    s.owner[k] = sp.owner[n];
    s.sample_triangle[k] = sp.sample_triangle[n];
    s.centroid[k] = sp.centroid[n];
    s.position[k] = sp.position[n];
    s.normal[k] = sp.normal[n];
    s.texel_world_size[k] = sp.texel_world_size[n];
    s.tangent[k] = sp.tangent[n];
    s.bitangent[k] = sp.bitangent[n];
  }
  return s;
}

namespace {

// dilate() with texels that are never filled (blocked[k] = 1, or null: none): the gaps between
// the pages of a scene bake, so that dilation stays inside each page.
std::size_t dilate_masked(image& img, std::vector<std::uint8_t>& filled, int rings, const std::uint8_t* blocked) {
  const std::size_t texels = std::size_t(img.width) * std::size_t(img.height);
  const int w = img.width, h = img.height, ch = img.channels;
  const auto neighbours = [&](std::size_t k, auto&& f) {
    const int x = int(k % std::size_t(w)), y = int(k / std::size_t(w));
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        f(std::size_t(ny) * std::size_t(w) + std::size_t(nx), nx, ny);
      }
  };
  // Candidates of a ring: empty texels next to a texel filled before it (the first ring: next to
  // any filled texel; later rings: next to the previous ring's texels). Kept sorted, so each
  // ring's writes are in texel order (they do not depend on it: a ring reads only older texels).
  std::vector<std::size_t> candidates, fresh;
  std::vector<std::uint8_t> queued(texels, 0);
  for (std::size_t k = 0; k < texels; ++k)
    if (!filled[k] && !(blocked && blocked[k])) {
      bool next_to_filled = false;
      neighbours(k, [&](std::size_t q, int, int) { next_to_filled = next_to_filled || filled[q]; });
      if (next_to_filled) {
        candidates.push_back(k);
        queued[k] = 1;
      }
    }
  std::size_t total = 0;
  for (int ring = 0; (rings < 0 || ring < rings) && !candidates.empty(); ++ring) {
    fresh.clear();
    for (std::size_t k : candidates) {
      float acc[4] = {0, 0, 0, 0};
      int n = 0;
      neighbours(k, [&](std::size_t q, int nx, int ny) {
        if (!filled[q]) return;
        const float* p = img.at(nx, ny);
        for (int c = 0; c < ch; ++c) acc[c] += p[c];
        ++n;
      });
      if (n == 0) continue;
      float* p = img.pixels.data() + k * std::size_t(ch);
      for (int c = 0; c < ch; ++c) p[c] = acc[c] / float(n);
      fresh.push_back(k);
    }
    // Marked after the ring: a ring reads only texels filled before it (order independent).
    for (std::size_t k : fresh) filled[k] = 1;
    total += fresh.size();
    candidates.clear();
    for (std::size_t k : fresh)
      neighbours(k, [&](std::size_t q, int, int) {
        if (!filled[q] && !queued[q] && !(blocked && blocked[q])) {
          queued[q] = 1;
          candidates.push_back(q);
        }
      });
    std::sort(candidates.begin(), candidates.end());
  }
  return total;
}

}  // namespace

std::size_t dilate(image& img, std::vector<std::uint8_t>& filled, int rings) {
  const std::size_t texels = std::size_t(img.width) * std::size_t(img.height);
  if (filled.size() != texels)
    throw_invalid_argument("dilate: filled has " + std::to_string(filled.size()) + " entries, the image " +
                           std::to_string(texels));
  if (rings < -1) throw_invalid_argument("dilate: rings " + std::to_string(rings) + " must be >= -1");
  return dilate_masked(img, filled, rings, nullptr);
}

namespace {

// The per-sample state of a bake (bake_lightmap's stages below), for sampled texels only.
struct sample_points {
  std::vector<std::size_t> texel_of;     // texel index of each sample
  std::vector<glm::vec3> positions, normals;
  std::vector<std::uint32_t> owner;      // the texel's owner triangle (its material)
  std::vector<glm::vec3> tangents, bitangents;  // the texel's lightmap tangent frame (with normals)
};

// A 2 x 2 block of texels of a scene bake's atlas that holds the radiance of the occluder-only
// triangles of one material (their UVs all point at the block's centre, where bilinear lookups
// read only the block).
struct occluder_block {
  std::array<std::size_t, 4> texels{};
  glm::vec3 emission{0.0f}, albedo{0.0f};
};

// Where the samples' values go: the texel grid of the bake (one lightmap, or the atlas of a scene
// bake's pages) and what its radiance textures hold besides the sampled texels. A plain
// bake_lightmap uses the grid alone (everything else empty: today's bake, bit for bit).
struct bake_layout {
  int width = 0, height = 0;
  std::vector<std::uint8_t> blocked;  // per texel, 1: never filled by dilation (outside every page); empty: none
  // (destination, source) texel pairs copied after dilation into radiance textures: the guard
  // rows and columns around each page repeat its edge, so that bilinear lookups near a page's
  // border read what clamp-to-edge would in a texture of its own.
  std::vector<std::pair<std::size_t, std::size_t>> guards;
  std::vector<glm::vec3> albedo, emission;  // per texel, or empty: the owner triangle's material
  std::vector<occluder_block> occluders;
  bool occluders_reflect = false;  // occluders add albedo x the mean irradiance / pi to their emission
  bool textured_first_pass = false;  // pass 1 sees the emission through a texture (emission images)
  const char* who = "bake_lightmap";

  const std::uint8_t* blocked_mask() const { return blocked.empty() ? nullptr : blocked.data(); }
};

// L1 SH per sample, coefficient-major (sh[k][i]).
using sh_planes = std::array<std::vector<glm::vec3>, 4>;

// What one pass gives per sample.
struct pass_values {
  std::vector<glm::vec3> e;
  sh_planes sh;                 // with directional outputs in this pass
  std::vector<hl2_cone> cone;   // with output_hl2 in this pass (reference make_frame(normal).t)
  std::vector<std::uint8_t> invalid;  // 1: the sample is inside geometry (filled, not computed)
};

// Step 2 of bake.hpp: the sampled texels, offset along their normals.
sample_points place_samples(const sparse_samples& s, const scene& sc, const bake_options& o, const bake_layout& layout,
                            bake_result& r) {
  const std::size_t texels = std::size_t(layout.width) * std::size_t(layout.height);
  const float min_offset = 2.0f * default_near_distance(sc);
  sample_points out;
  r.coverage.assign(texels, 0.0f);
  r.sampled.assign(texels, 0);
  for (std::size_t n = 0; n < s.size(); ++n) {
    const std::size_t k = s.texel[n];
    r.coverage[k] = s.coverage[n];
    if (s.coverage[n] > 0.0f) ++r.stats.covered_texels;
    if (s.sample_triangle[n] == lightmap_samples::no_triangle || !(s.coverage[n] >= o.min_coverage) || !(s.coverage[n] > 0.0f))
      continue;
    r.sampled[k] = 1;
    out.texel_of.push_back(k);
    const float offset = std::max(min_offset, o.offset_texels * s.texel_world_size[n]);
    out.positions.push_back(s.position[n] + offset * s.normal[n]);
    out.normals.push_back(s.normal[n]);
    out.owner.push_back(s.owner[n]);
    out.tangents.push_back(s.tangent[n]);
    out.bitangents.push_back(s.bitangent[n]);
  }
  r.stats.sampled_texels = out.texel_of.size();
  if (out.texel_of.empty())
    throw_invalid_argument(std::string(layout.who) + ": no texel is covered by a triangle (coverage >= min_coverage): nothing to bake");
  return out;
}

// Step 4's radiance texture for pass k > 1: emission + albedo E_{k-1} / pi of each texel's owner
// (or of the layout's per-texel images), dilated (at least 2 rings) so that hemicubes looking at
// chart borders do not see black; then the occluder blocks and the guards. With e = null (pass 1
// of a bake with emission images): the emission alone.
image pass_radiance_texture(const scene& sc, const sample_points& pts, const std::vector<glm::vec3>* e, const bake_options& o,
                            const bake_layout& layout) {
  image texture = image::make(layout.width, layout.height, 3);
  std::vector<std::uint8_t> filled(texture.pixels.size() / 3, 0);
  for (std::size_t i = 0; i < pts.texel_of.size(); ++i) {
    const std::size_t k = pts.texel_of[i];
    const material& m = sc.triangle_material(pts.owner[i]);
    const glm::vec3 emission = layout.emission.empty() ? m.emission : layout.emission[k];
    const glm::vec3 albedo = layout.albedo.empty() ? m.albedo : layout.albedo[k];
    const glm::vec3 l = e ? emission + albedo * (*e)[i] / pi_f : emission;
    std::memcpy(texture.pixels.data() + 3 * k, &l, sizeof l);
    filled[k] = 1;
  }
  dilate_masked(texture, filled, o.dilation < 0 ? -1 : std::max(o.dilation, 2), layout.blocked_mask());
  if (!layout.occluders.empty()) {
    // The occluders' coarse estimate: the mean irradiance of the samples of the previous pass.
    glm::dvec3 sum(0.0);
    if (e && layout.occluders_reflect)
      for (const glm::vec3& v : *e) sum += glm::dvec3(v);
    const glm::vec3 mean = pts.texel_of.empty() ? glm::vec3(0.0f) : glm::vec3(sum / double(pts.texel_of.size()));
    for (const occluder_block& b : layout.occluders) {
      const glm::vec3 l = b.emission + b.albedo * mean / pi_f;
      for (std::size_t k : b.texels) std::memcpy(texture.pixels.data() + 3 * k, &l, sizeof l);
    }
  }
  for (const auto& g : layout.guards)
    std::memcpy(texture.pixels.data() + 3 * g.first, texture.pixels.data() + 3 * g.second, 3 * sizeof(float));
  return texture;
}

}  // namespace

image bake_radiance_texture(const bake_input& input, const bake_options& o, const bake_result& r) {
  if (o.indirect_only)
    throw_invalid_argument("bake_radiance_texture: the bake is indirect_only: its irradiance lacks the first bounce");
  if (r.irradiance.width != o.width || r.irradiance.height != o.height || r.sampled.size() != std::size_t(o.width) * std::size_t(o.height))
    throw_invalid_argument("bake_radiance_texture: the result's size does not match options (" + std::to_string(o.width) + " x " +
                           std::to_string(o.height) + ")");
  const sparse_samples s = compute_sparse_samples(input, o.width, o.height);
  image texture = image::make(o.width, o.height, 3);
  std::vector<std::uint8_t> filled(texture.pixels.size() / 3, 0);
  for (std::size_t n = 0; n < s.size(); ++n) {
    const std::size_t k = s.texel[n];
    if (!r.sampled[k]) continue;
    const material m = input.scene.materials ? input.scene.materials[s.owner[n]] : material{};
    const glm::vec3 e(r.irradiance.pixels[3 * k], r.irradiance.pixels[3 * k + 1], r.irradiance.pixels[3 * k + 2]);
    const glm::vec3 l = m.emission + m.albedo * e / pi_f;
    std::memcpy(texture.pixels.data() + 3 * k, &l, sizeof l);
    filled[k] = 1;
  }
  dilate(texture, filled, o.dilation < 0 ? -1 : std::max(o.dilation, 2));
  return texture;
}

namespace {

// One pass through the cache (bake_options::use_cache).
pass_values cached_pass(const sample_points& pts, const irradiance_sampler& sampler, cache_options co, bool directional,
                        const std::function<bool(float)>& progress, bake_stats& stats) {
  const std::size_t count = pts.texel_of.size();
  co.directional = directional;
  co.fill_invalid = false;  // fill_invalid_samples dilates valid texels into them instead
  if (progress) co.progress = progress;
  cache_result cr = cache_irradiance(pts.positions.data(), pts.normals.data(), count, sampler, co);
  pass_values v;
  v.e = std::move(cr.irradiance);
  v.invalid.resize(count);
  for (std::size_t i = 0; i < count; ++i) v.invalid[i] = cr.valid[i] ? 0 : 1;
  if (directional) {
    for (auto& plane : v.sh) plane.resize(count);
    for (std::size_t i = 0; i < count; ++i)
      for (std::size_t c = 0; c < 4; ++c) v.sh[c][i] = cr.sh_l1[i][c];
    v.cone = std::move(cr.cone);
  }
  stats.hemicubes += cr.stats.hemicubes;
  stats.records += cr.stats.records;
  stats.passes.push_back(cr.stats);
  return v;
}

// One pass with a hemicube at every sample (use_cache = false: the reference), in blocks so that
// progress and cancellation stay live.
pass_values per_texel_pass(const sample_points& pts, const irradiance_sampler& sampler, const bake_options& o,
                           bool directional, const std::function<bool(float)>& progress, bake_stats& stats) {
  const auto tp = std::chrono::steady_clock::now();
  const std::size_t count = pts.texel_of.size();
  pass_values v;
  v.e.resize(count);
  v.invalid.assign(count, 0);
  if (directional) {
    for (auto& plane : v.sh) plane.assign(count, glm::vec3(0.0f));
    v.cone.assign(count, hl2_cone{});
  }
  const std::size_t block = 2048;
  for (std::size_t b = 0; b < count; b += block) {
    if (progress && !progress(float(b) / float(count)))
      throw error(status::cancelled, "bake_lightmap: cancelled by the progress callback");
    const std::size_t end = std::min(count, b + block);
    parallel_for(end - b, o.thread_count, 16, [&](int worker, std::size_t lo, std::size_t hi) {
      for (std::size_t i = b + lo; i < b + hi; ++i) {
        const cache_sample smp = sampler(worker, pts.positions[i], pts.normals[i]);
        v.e[i] = smp.irradiance;
        v.invalid[i] = smp.backface_fraction > o.cache.invalid_backface_fraction ? 1 : 0;
        if (directional) {
          for (std::size_t c = 0; c < 4; ++c) v.sh[c][i] = smp.sh_l1[c];
          v.cone[i] = rotate_hl2_cone(smp.cone, pts.normals[i], make_frame(pts.normals[i]).t);
        }
      }
    });
  }
  std::size_t invalid = 0;
  for (std::uint8_t f : v.invalid) invalid += f;
  cache_stats cs;
  cs.hemicubes = count;
  cs.records = count;
  cs.invalid_samples = invalid;
  cs.invalid_points = invalid;
  cs.seconds = seconds_since(tp);
  stats.hemicubes += count;
  stats.records += count;
  stats.passes.push_back(cs);
  return v;
}

// Per-sample values at samples inside geometry (invalid[i] = 1) replaced by those of the valid
// texels around them in the lightmap (texel dilation until every such texel is reached): the same
// chart, so the same side of the same surface, never a record across a wall.
class invalid_filler {
 public:
  invalid_filler(const sample_points& pts, const std::vector<std::uint8_t>& invalid, const bake_layout& layout)
      : pts_(pts), invalid_(invalid), layout_(layout), filled_(std::size_t(layout.width) * std::size_t(layout.height), 0) {
    for (std::size_t i = 0; i < invalid.size(); ++i) {
      if (!invalid[i]) filled_[pts.texel_of[i]] = 1;
      any_ = any_ || invalid[i];
    }
  }
  bool needed() const { return any_; }
  void operator()(std::vector<glm::vec3>& values) const {
    if (!any_) return;
    const std::size_t count = pts_.texel_of.size();
    image tmp = image::make(layout_.width, layout_.height, 3);
    for (std::size_t i = 0; i < count; ++i) std::memcpy(tmp.pixels.data() + 3 * pts_.texel_of[i], &values[i], sizeof(glm::vec3));
    std::vector<std::uint8_t> f = filled_;
    dilate_masked(tmp, f, -1, layout_.blocked_mask());
    for (std::size_t i = 0; i < count; ++i)
      if (invalid_[i]) std::memcpy(&values[i], tmp.pixels.data() + 3 * pts_.texel_of[i], sizeof(glm::vec3));
  }

 private:
  const sample_points& pts_;
  const std::vector<std::uint8_t>& invalid_;
  const bake_layout& layout_;
  std::vector<std::uint8_t> filled_;
  bool any_ = false;
};

// What the lights give per sample (step 3b), computed once: e and sh are added to every pass
// before its invalid samples are filled; hl2 (in the texel's lightmap frame) and the shadow mask
// are filled once after the passes and written with the outputs.
struct direct_values {
  std::vector<glm::vec3> e;
  sh_planes sh;                                // with output_sh_l1
  std::array<std::vector<glm::vec3>, 3> hl2;   // with output_hl2
  std::array<std::vector<glm::vec3>, 2> mask;  // with a shadow mask: channels (0, 1, 2) and (3, -, -)
};

// Step 3b: the lights' direct irradiance at every sample (parallel, in blocks so that
// cancellation stays live; deterministic: each sample's value depends on its point only).
direct_values direct_pass(const sample_points& pts, const scene& sc, const light_set& lights,
                          const bake_options& o, const std::function<bool()>& keep_going) {
  const std::size_t count = pts.texel_of.size();
  const bool mask = std::any_of(o.shadow_mask_lights.begin(), o.shadow_mask_lights.end(), [](int l) { return l >= 0; });
  direct_values d;
  d.e.assign(count, glm::vec3(0.0f));
  if (o.output_sh_l1)
    for (auto& plane : d.sh) plane.assign(count, glm::vec3(0.0f));
  if (o.output_hl2)
    for (auto& plane : d.hl2) plane.assign(count, glm::vec3(0.0f));
  if (mask)
    for (auto& plane : d.mask) plane.assign(count, glm::vec3(0.0f));
  const std::size_t block = 4096;
  for (std::size_t b = 0; b < count; b += block) {
    if (keep_going && !keep_going()) throw error(status::cancelled, "bake_lightmap: cancelled by the progress callback");
    const std::size_t end = std::min(count, b + block);
    parallel_for(end - b, o.thread_count, 64, [&](int, std::size_t lo, std::size_t hi) {
      std::vector<light_sample> per_light(lights.size());
      for (std::size_t i = b + lo; i < b + hi; ++i) {
        const glm::vec3 n = pts.normals[i];
        d.e[i] = direct_irradiance(sc, lights, pts.positions[i], n, o.direct, per_light.data());
        if (mask)
          for (std::size_t c = 0; c < 4; ++c) {
            const int l = o.shadow_mask_lights[c];
            if (l >= 0) d.mask[c / 3][i][int(c % 3)] = per_light[std::size_t(l)].visibility;
          }
        if (!o.output_sh_l1 && !o.output_hl2) continue;
        const frame f{pts.tangents[i], pts.bitangents[i], pts.normals[i]};
        std::array<glm::vec3, 3> basis{};  // the texel's HL2 vectors in world space
        if (o.output_hl2)
          for (std::size_t j = 0; j < 3; ++j) basis[j] = f.to_world(glm::vec3(hl2_basis[j][0], hl2_basis[j][1], hl2_basis[j][2]));
        for (const light_sample& ls : per_light) {
          const float cos_n = glm::dot(n, ls.direction);
          if (!(cos_n > 1e-4f)) continue;  // no light, or all of it at the horizon (E ~ 0)
          const glm::vec3 flux = ls.irradiance / cos_n;  // radiance x solid angle from direction w
          const glm::vec3& w = ls.direction;
          if (o.output_sh_l1) {
            d.sh[0][i] += 0.282094792f * flux;
            d.sh[1][i] += (0.488602512f * w.y) * flux;
            d.sh[2][i] += (0.488602512f * w.z) * flux;
            d.sh[3][i] += (0.488602512f * w.x) * flux;
          }
          if (o.output_hl2)
            for (std::size_t j = 0; j < 3; ++j) d.hl2[j][i] += std::max(0.0f, glm::dot(basis[j], w)) * flux;
        }
      }
    });
  }
  return d;
}

// A pass's irradiance (and SH, where the pass computed it) plus the lights' (step 3b).
void add_direct(const direct_values& d, pass_values& v) {
  for (std::size_t i = 0; i < v.e.size(); ++i) v.e[i] += d.e[i];
  for (std::size_t c = 0; c < 4; ++c)
    if (!v.sh[c].empty() && !d.sh[c].empty())
      for (std::size_t i = 0; i < v.e.size(); ++i) v.sh[c][i] += d.sh[c][i];
}

// The lights' HL2 values and shadow mask at samples inside geometry (valid = 0 after all passes)
// from the valid texels around them, as the passes' values are.
void fill_direct_outputs(const sample_points& pts, const std::vector<std::uint8_t>& valid, const bake_layout& layout,
                         direct_values& d) {
  std::vector<std::uint8_t> invalid(valid.size());
  for (std::size_t i = 0; i < valid.size(); ++i) invalid[i] = valid[i] ? 0 : 1;
  const invalid_filler fill(pts, invalid, layout);
  if (!fill.needed()) return;
  for (auto& plane : d.hl2)
    if (!plane.empty()) fill(plane);
  for (auto& plane : d.mask)
    if (!plane.empty()) fill(plane);
}

// Samples inside geometry get the values of the valid texels around them (invalid_filler). Used
// by both modes.
void fill_invalid_samples(const sample_points& pts, pass_values& v, const bake_layout& layout) {
  const invalid_filler fill(pts, v.invalid, layout);
  if (!fill.needed()) return;
  const std::size_t count = pts.texel_of.size();
  fill(v.e);
  for (auto& plane : v.sh)
    if (!plane.empty()) fill(plane);
  if (!v.cone.empty()) {
    // Cone coefficients term by term (neighbours on a chart share the normal and so the
    // reference tangent).
    std::vector<glm::vec3> plane(count);
    for (std::size_t t = 0; t < std::size_t(hl2_cone_terms); ++t) {
      for (std::size_t i = 0; i < count; ++i) plane[i] = v.cone[i].coefficients[t];
      fill(plane);
      for (std::size_t i = 0; i < count; ++i) v.cone[i].coefficients[t] = plane[i];
    }
  }
}

// Step 5 and 6: the lightmap images from the last pass (less the first with indirect_only),
// dilated around every chart.
void write_outputs(const sample_points& pts, const pass_values& last, const pass_values* first,
                   const direct_values* direct, const std::vector<std::uint8_t>& valid, const bake_options& o,
                   const bake_layout& layout, bake_result& r, std::vector<std::uint8_t>& filled) {
  const std::size_t texels = std::size_t(layout.width) * std::size_t(layout.height);
  const std::size_t count = pts.texel_of.size();
  r.irradiance = image::make(layout.width, layout.height, 3);
  r.valid.assign(texels, 0);
  filled.assign(texels, 0);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t k = pts.texel_of[i];
    glm::vec3 v = last.e[i];
    if (first) v = glm::max(v - first->e[i], glm::vec3(0.0f));
    std::memcpy(r.irradiance.pixels.data() + 3 * k, &v, sizeof v);
    filled[k] = 1;
    r.valid[k] = valid[i];
    if (!valid[i]) ++r.stats.invalid_texels;
  }
  // Per-sample values written into images, each dilated from the same mask as the irradiance.
  const auto to_image = [&](const auto& value_of) {
    image img = image::make(layout.width, layout.height, 3);
    for (std::size_t i = 0; i < count; ++i) {
      const glm::vec3 v = value_of(i);
      std::memcpy(img.pixels.data() + 3 * pts.texel_of[i], &v, sizeof v);
    }
    std::vector<std::uint8_t> f = filled;
    dilate_masked(img, f, o.dilation, layout.blocked_mask());
    return img;
  };
  if (o.output_sh_l1)
    for (std::size_t j = 0; j < 4; ++j)
      r.sh_l1[j] = to_image([&](std::size_t i) { return first ? last.sh[j][i] - first->sh[j][i] : last.sh[j][i]; });
  if (o.output_hl2) {
    std::vector<std::array<glm::vec3, 3>> h(count);
    for (std::size_t i = 0; i < count; ++i) {
      hl2_cone c = last.cone[i];
      if (first)
        for (std::size_t t = 0; t < std::size_t(hl2_cone_terms); ++t) c.coefficients[t] -= first->cone[i].coefficients[t];
      h[i] = hl2_from_cone(c, frame{pts.tangents[i], pts.bitangents[i], pts.normals[i]});
      if (direct && !first)
        for (std::size_t j = 0; j < 3; ++j) h[i][j] += direct->hl2[j][i];
    }
    for (std::size_t j = 0; j < 3; ++j) r.hl2[j] = to_image([&](std::size_t i) { return h[i][j]; });
  }
  if (direct && !direct->mask[0].empty()) {
    const image rgb = to_image([&](std::size_t i) { return direct->mask[0][i]; });
    const image alpha = to_image([&](std::size_t i) { return direct->mask[1][i]; });
    r.shadow_mask = image::make(layout.width, layout.height, 4);
    for (std::size_t k = 0; k < texels; ++k) {
      for (std::size_t c = 0; c < 3; ++c) r.shadow_mask.pixels[4 * k + c] = rgb.pixels[3 * k + c];
      r.shadow_mask.pixels[4 * k + 3] = alpha.pixels[3 * k];
    }
  }
  r.stats.dilated_texels = dilate_masked(r.irradiance, filled, o.dilation, layout.blocked_mask());
}

// Steps 2-6 of bake.hpp on the samples of a layout (one lightmap, or a scene bake's atlas):
// the passes, the lights, the outputs. `filled` receives the texels written or dilated.
bake_result bake_samples(sparse_samples s, const std::shared_ptr<const scene>& sc, const bake_options& o,
                         const bake_layout& layout, std::chrono::steady_clock::time_point t0,
                         std::vector<std::uint8_t>& filled) {
  bake_result r;
  r.stats.texels = std::size_t(layout.width) * std::size_t(layout.height);
  r.stats.coverage_seconds = seconds_since(t0);
  r.stats.overlapping_texels = s.overlapping_texels;
  const sample_points pts = place_samples(s, *sc, o, layout, r);
  const std::size_t count = pts.texel_of.size();
  s = sparse_samples{};  // what the passes need is in pts now

  const int workers = resolve_thread_count(o.thread_count);
  const bool directional = o.output_sh_l1 || o.output_hl2;
  cache_options co = o.cache;
  co.thread_count = o.thread_count;
  co.progress = nullptr;
  std::vector<std::uint8_t> valid(count, 1);
  std::vector<std::uint8_t> inside(count, 0);  // per sample: found inside geometry by an earlier pass
  pass_values current, first;
  const light_set lights(o.lights.data(), o.lights.size());
  direct_values direct;
  if (!lights.empty()) {
    const auto td = std::chrono::steady_clock::now();
    // The ray structure now, so that an Embree failure is an error here, not a slower fallback.
    prepare_rays(*sc);
    std::function<bool()> keep_going;
    if (o.progress) keep_going = [&] { return o.progress(0.0f); };
    direct = direct_pass(pts, *sc, lights, o, keep_going);
    r.stats.direct_seconds = seconds_since(td);
  }
  image texture;
  radiance_texture texture_view;

  // The cache's fraction can step back between rounds; the bake reports the running maximum.
  float reported = 0.0f;
  const auto report = [&](float f) {
    reported = std::max(reported, std::min(f, 1.0f));
    return o.progress(reported);
  };
  for (int pass = 0; pass < o.bounces; ++pass) {
    if (o.progress && !report(float(pass) / float(o.bounces)))
      throw error(status::cancelled, "bake_lightmap: cancelled by the progress callback");
    // Directional integration only where its result is used: the last pass, and the first
    // when the indirect part is wanted (last minus first).
    const bool pass_directional = directional && (pass == o.bounces - 1 || (pass == 0 && o.indirect_only));
    hemicube_sampler_options so;
    so.resolution = o.resolution;
    so.roll = true;
    so.raster.sky = o.environment;
    so.raster.edge_coverage = o.edge_coverage;
    so.sh_l1 = pass_directional && o.output_sh_l1;  // the cheap SH (cache.hpp), not the integrator's directional pass
    so.hl2_cone = pass_directional && o.output_hl2;
    if (pass > 0 || layout.textured_first_pass) {
      texture = pass_radiance_texture(*sc, pts, pass > 0 ? &current.e : nullptr, o, layout);
      texture_view = radiance_texture(texture);
      so.texture = &texture_view;
    }
    const irradiance_sampler sampler = make_hemicube_sampler(sc, so, workers);
    const float base = float(pass) / float(o.bounces), span = 1.0f / float(o.bounces);
    std::function<bool(float)> pass_progress;
    if (o.progress) pass_progress = [&](float f) { return report(base + span * f); };
    // Points an earlier pass found inside geometry are inside in this one too (the geometry is
    // the same): the cache renders no hemicube for them.
    if (pass > 0) {
      for (std::size_t i = 0; i < count; ++i) inside[i] = std::uint8_t(valid[i] ? 0 : 1);
      co.known_inside = inside.data();
    }
    current = o.use_cache ? cached_pass(pts, sampler, co, pass_directional, pass_progress, r.stats)
                          : per_texel_pass(pts, sampler, o, pass_directional, pass_progress, r.stats);
    if (!lights.empty()) add_direct(direct, current);
    fill_invalid_samples(pts, current, layout);
    for (std::size_t i = 0; i < count; ++i) valid[i] = std::uint8_t(valid[i] & (current.invalid[i] ? 0 : 1));
    if (pass == 0 && o.indirect_only) first = current;
  }
  if (o.progress && !report(1.0f)) throw error(status::cancelled, "bake_lightmap: cancelled by the progress callback");
  if (!lights.empty()) fill_direct_outputs(pts, valid, layout, direct);
  write_outputs(pts, current, o.indirect_only ? &first : nullptr, lights.empty() ? nullptr : &direct, valid, o, layout, r,
                filled);
  r.stats.seconds = seconds_since(t0);
  return r;
}

void check_environment(const char* who, const bake_options& o) {
  if (!o.environment) return;
  try {
    o.environment->validate();
  } catch (const error& e) {
    throw_invalid_argument(std::string(who) + ": environment: " + e.what());
  }
}

}  // namespace

bake_result bake_lightmap(const bake_input& input, const bake_options& o) {
  const auto t0 = std::chrono::steady_clock::now();
  check_options(o);
  check_input("bake_lightmap", input);
  const std::shared_ptr<const scene> sc = scene::create(input.scene);
  check_environment("bake_lightmap", o);
  bake_layout layout;
  layout.width = o.width;
  layout.height = o.height;
  std::vector<std::uint8_t> filled;
  return bake_samples(compute_sparse_samples(input, o.width, o.height), sc, o, layout, t0, filled);
}

// ---- bake_scene: pages and occluders -------------------------------------------------------------

namespace {

// Checks a page's optional material image: its size, channels and every value.
void check_page_image(const char* who, std::size_t p, const char* name, const image& img, const lightmap_page& page, float hi) {
  if (img.width == 0 && img.height == 0 && img.pixels.empty()) return;
  const std::string what = std::string(who) + ": pages[" + std::to_string(p) + "]." + name;
  if (img.width != page.width || img.height != page.height || img.channels != 3 ||
      img.pixels.size() != std::size_t(img.width) * std::size_t(img.height) * 3)
    throw_invalid_argument(what + " is " + std::to_string(img.width) + " x " + std::to_string(img.height) + " with " +
                           std::to_string(img.channels) + " channels: it must be " + std::to_string(page.width) + " x " +
                           std::to_string(page.height) + " RGB (3 channels), the page's size");
  for (std::size_t k = 0; k < img.pixels.size(); ++k)
    if (!(img.pixels[k] >= 0.0f && img.pixels[k] <= hi)) {
      const std::size_t t = k / 3;
      throw_invalid_argument(what + " (" + std::to_string(t % std::size_t(img.width)) + ", " + std::to_string(t / std::size_t(img.width)) +
                             ") = " + num(img.pixels[k]) + " is outside [0, " + num(hi) + "]");
    }
}

// The atlas of a scene bake: pages stacked vertically in one texel grid, each with guard rows
// and columns between it and the rest (copies of its edge in radiance textures, never filled by
// dilation), then the occluders' 2 x 2 blocks.
struct scene_atlas {
  bake_layout layout;
  std::vector<int> page_y;  // first row of each page
};

scene_atlas make_atlas(const std::vector<lightmap_page>& pages, std::size_t occluder_materials) {
  scene_atlas a;
  int width = 0;
  for (const lightmap_page& p : pages) width = std::max(width, p.width);
  if (occluder_materials > 0) width = std::max(width, 2);
  const std::size_t blocks_per_strip = std::size_t(width / 2);
  const std::size_t strips = occluder_materials == 0 ? 0 : (occluder_materials + blocks_per_strip - 1) / blocks_per_strip;
  std::size_t rows = 0;
  for (std::size_t p = 0; p < pages.size(); ++p) {
    if (p > 0) ++rows;  // guard above
    a.page_y.push_back(int(rows));
    rows += std::size_t(pages[p].height);
    if (p + 1 < pages.size() || strips > 0) ++rows;  // guard below
  }
  const std::size_t occluder_y = rows;
  rows += 2 * strips;
  if (rows > std::size_t(std::numeric_limits<int>::max() / 2))
    throw_invalid_argument("bake_scene: the pages' atlas would have " + std::to_string(rows) + " rows: too many");
  bake_layout& l = a.layout;
  l.width = width;
  l.height = int(rows);
  const std::size_t w = std::size_t(width);
  l.blocked.assign(w * rows, 1);
  for (std::size_t p = 0; p < pages.size(); ++p) {
    const std::size_t y0 = std::size_t(a.page_y[p]), pw = std::size_t(pages[p].width), ph = std::size_t(pages[p].height);
    for (std::size_t y = y0; y < y0 + ph; ++y)
      std::fill(l.blocked.begin() + std::ptrdiff_t(y * w), l.blocked.begin() + std::ptrdiff_t(y * w + pw), std::uint8_t(0));
    // Guards: the row above and below (where present) and the column right of the page (where
    // the atlas is wider), corners included, each a copy of the nearest texel of the page.
    const std::size_t gy0 = p > 0 ? y0 - 1 : y0;
    const std::size_t gy1 = (p + 1 < pages.size() || strips > 0) ? y0 + ph : y0 + ph - 1;  // inclusive
    const std::size_t gx1 = pw < w ? pw : pw - 1;                                            // inclusive
    for (std::size_t y = gy0; y <= gy1; ++y)
      for (std::size_t x = 0; x <= gx1; ++x) {
        const std::size_t sx = std::min(x, pw - 1), sy = std::clamp(y, y0, y0 + ph - 1);
        if (sx != x || sy != y) l.guards.emplace_back(y * w + x, sy * w + sx);
      }
  }
  for (std::size_t m = 0; m < occluder_materials; ++m) {
    const std::size_t x = 2 * (m % blocks_per_strip), y = occluder_y + 2 * (m / blocks_per_strip);
    occluder_block b;
    b.texels = {y * w + x, y * w + x + 1, (y + 1) * w + x, (y + 1) * w + x + 1};
    l.occluders.push_back(b);
  }
  return a;
}

// The combined geometry of a scene bake: the input's triangles with lightmap UVs in the atlas
// (vertices shared by meshes duplicated, occluders' corners pointing at their material's block)
// and, per vertex, its page UV (for the per-page samples).
struct scene_geometry {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> page_uvs;
  std::vector<std::uint32_t> indices;
  std::vector<int> triangle_page;  // per triangle: page, or -1 (occluder)
  std::vector<material> occluder_materials;
  std::vector<std::size_t> triangle_block;  // per triangle: its occluder block (occluders only)
};

std::string uv_text(const glm::vec2& v) { return "(" + num(v.x) + ", " + num(v.y) + ")"; }

// Checks the meshes (ranges, pages, scale/offset) and maps every vertex of every mesh to its
// page, naming the mesh in every error.
scene_geometry make_scene_geometry(const char* who, const scene_bake_input& in) {
  const scene_desc& d = in.geometry.scene;
  const std::size_t T = d.triangle_count;
  std::size_t next = 0;
  for (std::size_t m = 0; m < in.meshes.size(); ++m) {
    const bake_mesh& mesh = in.meshes[m];
    const std::string name = std::string(who) + ": meshes[" + std::to_string(m) + "]";
    if (mesh.first_triangle != next)
      throw_invalid_argument(name + ".first_triangle = " + std::to_string(mesh.first_triangle) + " must be " + std::to_string(next) +
                             " (meshes cover the triangles in order, each starting where the previous one ends)");
    if (mesh.triangle_count > T - next)
      throw_invalid_argument(name + ": triangles [" + std::to_string(mesh.first_triangle) + ", " +
                             std::to_string(mesh.first_triangle + mesh.triangle_count) + ") run past the scene's " +
                             std::to_string(T) + " triangles");
    next += mesh.triangle_count;
    if (mesh.page < -1 || (mesh.page >= 0 && std::size_t(mesh.page) >= in.pages.size()))
      throw_invalid_argument(name + ".page = " + std::to_string(mesh.page) + " is not -1 (occluder only) or a page index (" +
                             std::to_string(in.pages.size()) + " pages)");
    for (int c = 0; c < 2; ++c)
      if (!std::isfinite(mesh.uv_scale[c]) || !std::isfinite(mesh.uv_offset[c]))
        throw_invalid_argument(name + ": uv_scale " + uv_text(mesh.uv_scale) + " or uv_offset " + uv_text(mesh.uv_offset) +
                               " is not finite");
  }
  if (next != T)
    throw_invalid_argument(std::string(who) + ": the meshes cover " + std::to_string(next) + " of the scene's " + std::to_string(T) +
                           " triangles: every triangle must belong to a mesh");

  scene_geometry g;
  constexpr std::uint32_t none = 0xffffffffu;
  // Meshes come in triangle order, so a vertex's copy for its latest user is all that is needed.
  std::vector<std::uint32_t> last_user(d.vertex_count, none), last_copy(d.vertex_count, none);
  const auto add_vertex = [&](std::uint32_t v, const glm::vec2& page_uv) {
    g.positions.push_back(d.positions[v]);
    if (in.geometry.normals) g.normals.push_back(in.geometry.normals[v]);
    g.page_uvs.push_back(page_uv);
    return std::uint32_t(g.positions.size() - 1);
  };
  std::map<std::array<float, 6>, std::size_t> blocks;  // occluder material -> block
  g.indices.reserve(3 * T);
  g.triangle_page.reserve(T);
  g.triangle_block.assign(T, 0);
  for (std::size_t m = 0; m < in.meshes.size(); ++m) {
    const bake_mesh& mesh = in.meshes[m];
    const auto mu = std::uint32_t(m);
    for (std::size_t t = mesh.first_triangle; t < mesh.first_triangle + mesh.triangle_count; ++t) {
      g.triangle_page.push_back(mesh.page);
      if (mesh.page < 0) {
        // Occluder: its own three corners (their UVs point at its material's block, set below).
        const material mat = d.materials ? d.materials[t] : material{};
        const std::array<float, 6> key{{mat.emission.x, mat.emission.y, mat.emission.z, mat.albedo.x, mat.albedo.y, mat.albedo.z}};
        const auto it = blocks.emplace(key, g.occluder_materials.size()).first;
        if (it->second == g.occluder_materials.size()) g.occluder_materials.push_back(mat);
        g.triangle_block[t] = it->second;
        for (int c = 0; c < 3; ++c) g.indices.push_back(add_vertex(d.indices[3 * t + std::size_t(c)], glm::vec2(0.0f)));
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = d.indices[3 * t + std::size_t(c)];
        std::uint32_t out;
        if (last_user[v] == mu) {
          out = last_copy[v];
        } else {
          // uv' = uv * scale + offset, in float (the engine's arithmetic).
          const glm::vec2 q = d.lightmap_uvs[v] * mesh.uv_scale + mesh.uv_offset;
          if (!(q.x >= 0.0f && q.x <= 1.0f && q.y >= 0.0f && q.y <= 1.0f))
            throw_invalid_argument(std::string(who) + ": meshes[" + std::to_string(m) + "] (page " + std::to_string(mesh.page) +
                                   "): lightmap_uvs[" + std::to_string(v) + "] * uv_scale + uv_offset = " + uv_text(q) +
                                   " is outside [0, 1]");
          out = add_vertex(v, q);
          last_user[v] = mu;
          last_copy[v] = out;
        }
        g.indices.push_back(out);
      }
    }
  }
  return g;
}

}  // namespace

scene_bake_result bake_scene(const scene_bake_input& input, const bake_options& o) {
  const char* who = "bake_scene";
  const auto t0 = std::chrono::steady_clock::now();
  check_options(o, who, false);
  const scene_desc& d = input.geometry.scene;
  if (input.pages.empty()) throw_invalid_argument(std::string(who) + ": there are no pages (scene_bake_input::pages is empty)");
  for (std::size_t p = 0; p < input.pages.size(); ++p) {
    const lightmap_page& page = input.pages[p];
    check_size((std::string(who) + ": pages[" + std::to_string(p) + "]").c_str(), page.width, page.height);
    check_page_image(who, p, "albedo", page.albedo, page, 1.0f);
    check_page_image(who, p, "emission", page.emission, page, max_radiance);
  }
  check_input(who, input.geometry, false);
  check_environment(who, o);
  const scene_geometry g = make_scene_geometry(who, input);

  // The atlas, and the occluders' UVs at the centre of their material's block.
  scene_atlas atlas = make_atlas(input.pages, g.occluder_materials.size());
  bake_layout& layout = atlas.layout;
  layout.who = who;
  layout.occluders_reflect = input.occluders == occluder_radiance::emission_plus_mean_bounce;
  const std::size_t W = std::size_t(layout.width);
  for (std::size_t b = 0; b < g.occluder_materials.size(); ++b) {
    layout.occluders[b].emission = g.occluder_materials[b].emission;
    layout.occluders[b].albedo = g.occluder_materials[b].albedo;
  }
  std::vector<glm::vec2> atlas_uvs(g.positions.size());
  const std::size_t T = d.triangle_count;
  for (std::size_t t = 0; t < T; ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = g.indices[3 * t + std::size_t(c)];
      const int p = g.triangle_page[t];
      if (p < 0) {
        const std::size_t k = layout.occluders[g.triangle_block[t]].texels[0];
        atlas_uvs[v] = glm::vec2(float(double(k % W + 1) / double(W)), float(double(k / W + 1) / double(layout.height)));
      } else {
        const lightmap_page& page = input.pages[std::size_t(p)];
        const glm::vec2 q = g.page_uvs[v];
        atlas_uvs[v] = glm::vec2(float(double(q.x) * page.width / double(W)),
                                 float((double(q.y) * page.height + atlas.page_y[std::size_t(p)]) / double(layout.height)));
      }
    }
  scene_desc combined = d;
  combined.positions = g.positions.data();
  combined.vertex_count = g.positions.size();
  combined.indices = g.indices.data();
  combined.lightmap_uvs = atlas_uvs.data();
  const std::shared_ptr<const scene> sc = scene::create(combined);

  // Step 1 per page, in the page's own texel grid (its UVs), merged into the atlas (pages in
  // order: the atlas texel indices stay increasing).
  sparse_samples s;
  const std::size_t texels = W * std::size_t(layout.height);
  constexpr std::uint32_t none = lightmap_samples::no_triangle;
  s.width = layout.width;
  s.height = layout.height;
  std::vector<std::size_t> page_overlapping(input.pages.size(), 0);
  for (std::size_t p = 0; p < input.pages.size(); ++p) {
    const lightmap_page& page = input.pages[p];
    // The page's triangles with compact vertex arrays.
    std::vector<std::uint32_t> tris, remap(g.positions.size(), none), idx;
    std::vector<glm::vec3> pos, nrm;
    std::vector<glm::vec2> uvs;
    std::vector<material> mats;
    std::size_t mesh = 0;
    for (std::size_t t = 0; t < T; ++t) {
      if (g.triangle_page[t] != int(p)) continue;
      while (t >= input.meshes[mesh].first_triangle + input.meshes[mesh].triangle_count) ++mesh;
      const std::uint32_t* ti = g.indices.data() + 3 * t;
      // A triangle with 3D area but none in the page (the test compute_lightmap_samples makes),
      // named by its mesh.
      const glm::dvec2 a = glm::dvec2(g.page_uvs[ti[0]]) * glm::dvec2(page.width, page.height);
      const glm::dvec2 b = glm::dvec2(g.page_uvs[ti[1]]) * glm::dvec2(page.width, page.height);
      const glm::dvec2 c = glm::dvec2(g.page_uvs[ti[2]]) * glm::dvec2(page.width, page.height);
      const glm::dvec3 p0(g.positions[ti[0]]), p1(g.positions[ti[1]]), p2(g.positions[ti[2]]);
      if (glm::length(glm::cross(p1 - p0, p2 - p0)) > 0.0 &&
          !(0.5 * std::fabs(cross2(a, b, c)) > 1e-12 * double(page.width) * double(page.height)))
        throw_invalid_argument(std::string(who) + ": meshes[" + std::to_string(mesh) + "] triangle " +
                               std::to_string(t - input.meshes[mesh].first_triangle) + " (scene triangle " + std::to_string(t) +
                               ") has zero area in its page's UV space (but not in 3D): it would get no texels");
      tris.push_back(std::uint32_t(t));
      mats.push_back(d.materials ? d.materials[t] : material{});
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = ti[k];
        if (remap[v] == none) {
          remap[v] = std::uint32_t(pos.size());
          pos.push_back(g.positions[v]);
          uvs.push_back(g.page_uvs[v]);
          if (!g.normals.empty()) nrm.push_back(g.normals[v]);
        }
        idx.push_back(remap[v]);
      }
    }
    if (tris.empty()) continue;  // an empty page: all dilation (nothing to fill from)
    bake_input sub;
    sub.scene.positions = pos.data();
    sub.scene.vertex_count = pos.size();
    sub.scene.indices = idx.data();
    sub.scene.triangle_count = tris.size();
    sub.scene.materials = mats.data();
    sub.scene.lightmap_uvs = uvs.data();
    sub.normals = nrm.empty() ? nullptr : nrm.data();
    sparse_samples ps = compute_sparse_samples(sub, page.width, page.height);
    page_overlapping[p] = ps.overlapping_texels;
    s.overlapping_texels += ps.overlapping_texels;
    const std::size_t y0 = std::size_t(atlas.page_y[p]);
    if (s.size() == 0 && y0 == 0 && std::size_t(page.width) == W) {
      // The first page at the atlas's origin with its width: its texel indices are the atlas's;
      // taken over in place (no second copy of the samples at the peak).
      sparse_samples moved = std::move(ps);
      for (std::size_t n = 0; n < moved.size(); ++n) {
        moved.owner[n] = tris[moved.owner[n]];
        moved.sample_triangle[n] = moved.sample_triangle[n] == none ? none : tris[moved.sample_triangle[n]];
        moved.centroid[n] = glm::vec2(float(double(moved.centroid[n].x) * page.width / double(W)),
                                      float((double(moved.centroid[n].y) * page.height) / double(layout.height)));
      }
      moved.width = layout.width;
      moved.height = layout.height;
      s = std::move(moved);
      continue;
    }
    for (std::size_t n = 0; n < ps.size(); ++n) {
      const std::size_t j = ps.texel[n], x = j % std::size_t(page.width), y = j / std::size_t(page.width);
      s.texel.push_back((y0 + y) * W + x);
      s.coverage.push_back(ps.coverage[n]);
      s.owner.push_back(tris[ps.owner[n]]);
      s.sample_triangle.push_back(ps.sample_triangle[n] == none ? none : tris[ps.sample_triangle[n]]);
      s.centroid.emplace_back(float(double(ps.centroid[n].x) * page.width / double(W)),
                              float((double(ps.centroid[n].y) * page.height + double(y0)) / double(layout.height)));
      s.position.push_back(ps.position[n]);
      s.normal.push_back(ps.normal[n]);
      s.texel_world_size.push_back(ps.texel_world_size[n]);
      s.tangent.push_back(ps.tangent[n]);
      s.bitangent.push_back(ps.bitangent[n]);
    }
  }

  // Per-texel materials where a page has images (the other pages: their owners' materials).
  const bool any_albedo = std::any_of(input.pages.begin(), input.pages.end(), [](const lightmap_page& p) { return p.albedo.width > 0; });
  const bool any_emission = std::any_of(input.pages.begin(), input.pages.end(), [](const lightmap_page& p) { return p.emission.width > 0; });
  if (any_albedo) layout.albedo.assign(texels, glm::vec3(0.0f));
  if (any_emission) layout.emission.assign(texels, glm::vec3(0.0f));
  layout.textured_first_pass = any_emission;
  if (any_albedo || any_emission) {
    // The page of every atlas row (-1: a guard or the occluders' blocks).
    std::vector<int> row_page(std::size_t(layout.height), -1);
    for (std::size_t p = 0; p < input.pages.size(); ++p)
      for (int y = 0; y < input.pages[p].height; ++y) row_page[std::size_t(atlas.page_y[p] + y)] = int(p);
    for (std::size_t n = 0; n < s.size(); ++n) {
      const std::size_t k = s.texel[n];
      const int p = row_page[k / W];
      const lightmap_page& page = input.pages[std::size_t(p)];
      const int x = int(k % W), y = int(k / W) - atlas.page_y[std::size_t(p)];
      const material m = d.materials ? d.materials[s.owner[n]] : material{};
      if (any_albedo)
        layout.albedo[k] = page.albedo.width > 0 ? glm::vec3(page.albedo.at(x, y)[0], page.albedo.at(x, y)[1], page.albedo.at(x, y)[2])
                                                 : m.albedo;
      if (any_emission)
        layout.emission[k] = page.emission.width > 0
                                 ? glm::vec3(page.emission.at(x, y)[0], page.emission.at(x, y)[1], page.emission.at(x, y)[2])
                                 : m.emission;
    }
  }

  std::vector<std::uint8_t> filled;
  bake_result all = bake_samples(std::move(s), sc, o, layout, t0, filled);

  // Per page: the atlas rows of the page.
  scene_bake_result out;
  out.pages.resize(input.pages.size());
  for (std::size_t p = 0; p < input.pages.size(); ++p) {
    const lightmap_page& page = input.pages[p];
    bake_result& r = out.pages[p];
    const std::size_t y0 = std::size_t(atlas.page_y[p]), pw = std::size_t(page.width), ph = std::size_t(page.height);
    const auto crop = [&](const image& img) {
      if (img.width == 0) return image{};
      image c = image::make(page.width, page.height, img.channels);
      const std::size_t ch = std::size_t(img.channels);
      for (std::size_t y = 0; y < ph; ++y)
        std::memcpy(c.pixels.data() + y * pw * ch, img.pixels.data() + ((y0 + y) * W) * ch, pw * ch * sizeof(float));
      return c;
    };
    const auto crop_bytes = [&](const auto& v) {
      std::remove_cv_t<std::remove_reference_t<decltype(v)>> c(pw * ph);
      for (std::size_t y = 0; y < ph; ++y)
        std::copy_n(v.begin() + std::ptrdiff_t((y0 + y) * W), pw, c.begin() + std::ptrdiff_t(y * pw));
      return c;
    };
    r.irradiance = crop(all.irradiance);
    r.coverage = crop_bytes(all.coverage);
    r.valid = crop_bytes(all.valid);
    r.sampled = crop_bytes(all.sampled);
    for (std::size_t j = 0; j < 4; ++j) r.sh_l1[j] = crop(all.sh_l1[j]);
    for (std::size_t j = 0; j < 3; ++j) r.hl2[j] = crop(all.hl2[j]);
    r.shadow_mask = crop(all.shadow_mask);
    const std::vector<std::uint8_t> page_filled = crop_bytes(filled);
    r.stats.texels = pw * ph;
    r.stats.overlapping_texels = page_overlapping[p];
    for (std::size_t k = 0; k < pw * ph; ++k) {
      if (r.coverage[k] > 0.0f) ++r.stats.covered_texels;
      if (r.sampled[k]) ++r.stats.sampled_texels;
      if (r.sampled[k] && !r.valid[k]) ++r.stats.invalid_texels;
      if (!r.sampled[k] && page_filled[k]) ++r.stats.dilated_texels;
    }
  }
  out.stats = std::move(all.stats);
  out.stats.texels = 0;
  for (const bake_result& r : out.pages) out.stats.texels += r.stats.texels;
  return out;
}

image bake_mask_image(const bake_result& result) {
  const image& e = result.irradiance;
  const std::size_t texels = std::size_t(e.width) * std::size_t(e.height);
  if (result.coverage.size() != texels || result.valid.size() != texels || result.sampled.size() != texels)
    throw_invalid_argument("bake_mask_image: the result's per-texel arrays do not match its irradiance image");
  image m = image::make(e.width, e.height, 3);
  for (std::size_t k = 0; k < texels; ++k) {
    m.pixels[3 * k] = result.coverage[k];
    m.pixels[3 * k + 1] = float(result.valid[k]);
    m.pixels[3 * k + 2] = float(result.sampled[k]);
  }
  return m;
}

}  // namespace hemilight
