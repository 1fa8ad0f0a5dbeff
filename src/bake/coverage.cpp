// Step 1 of the baker: exact UV coverage (Sutherland-Hodgman clips in double) and each covered
// texel's sample point (coverage.hpp; bake.hpp: compute_lightmap_samples, clip_triangle_to_texel,
// lightmap_tangent_frame).
#include "coverage.hpp"

#include "checks.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

namespace hemilight {

namespace bake_detail {

namespace {

// Per-triangle data in double: UVs in texel units, 3D vertices, areas.
struct tri_data {
  glm::dvec2 t[3];      // texel units
  double uv_area = 0;   // texel units, absolute
  double area3 = 0;     // scene units^2
  bool drawn = false;   // covers texels: not degenerate (is_degenerate_triangle) and with UV area
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
  r.drawn = !is_degenerate_triangle(d.positions[idx[0]], d.positions[idx[1]], d.positions[idx[2]]);
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

// Pass A's sums per covered texel: a slot per texel, made when a triangle first covers it.
struct coverage_slots {
  static constexpr std::uint32_t no_slot = 0xffffffffu;
  std::vector<std::uint32_t> slot_of;  // per texel of the lightmap: its slot, or no_slot
  std::vector<std::size_t> texel;      // per slot: its texel
  std::vector<double> sum_area, owner_area;
  std::vector<glm::dvec2> sum_centroid, owner_centroid;
  std::vector<std::uint32_t> owner;
};

// The triangles in texel units. Degenerate ones cover nothing and are counted; a triangle with 3D
// area but (next to) no UV area would get no texels (a broken unwrap): refused with strict, else
// it covers nothing and is counted, the first remembered.
std::vector<tri_data> triangles_in_texels(const char* who, const scene_desc& d, int width, int height, bool strict,
                                          sparse_samples& counts) {
  std::vector<tri_data> tris(d.triangle_count);
  for (std::size_t i = 0; i < d.triangle_count; ++i) {
    tri_data& t = tris[i] = make_tri(d, i, width, height);
    if (!t.drawn) {
      ++counts.degenerate_triangles;
    } else if (!(t.uv_area > 1e-12 * double(width) * double(height))) {
      if (strict)
        throw_invalid_argument(std::string(who) + ": triangle " + std::to_string(i) +
                               " has zero area in lightmap UV space (but not in 3D): it would get no texels");
      if (counts.no_uv_area_triangles++ == 0) counts.first_no_uv_area_triangle = i;
      t.drawn = false;
    }
  }
  return tris;
}

// Pass A: coverage sum, area-weighted centroid, owner (largest area, ties to the lower index:
// triangles are visited in index order and only a strictly larger area replaces the owner).
// Per covered texel: a slot, made when a triangle first covers it (the sums per texel are
// formed in triangle order whatever the slot).
coverage_slots accumulate_coverage(const char* who, const std::vector<tri_data>& tris, int width, int height) {
  constexpr std::uint32_t none = lightmap_samples::no_triangle;
  constexpr std::uint32_t no_slot = coverage_slots::no_slot;
  coverage_slots s;
  s.slot_of.assign(std::size_t(width) * std::size_t(height), no_slot);
  for (std::size_t i = 0; i < tris.size(); ++i)
    for_each_texel_in_bounds(tris[i], width, height, [&](int x, int y, std::size_t k) {
      const clip_d c = clip_texel(tris[i].t, x, y);
      if (!(c.area > 0.0)) return;
      std::uint32_t q = s.slot_of[k];
      if (q == no_slot) {
        if (s.texel.size() >= std::size_t(no_slot))
          throw error(status::out_of_memory, std::string(who) + ": more than 2^32 - 1 covered texels");
        q = s.slot_of[k] = std::uint32_t(s.texel.size());
        s.texel.push_back(k);
        s.sum_area.push_back(0.0);
        s.owner_area.push_back(0.0);
        s.sum_centroid.emplace_back(0.0);
        s.owner_centroid.emplace_back(0.0);
        s.owner.push_back(none);
      }
      s.sum_area[q] += c.area;
      s.sum_centroid[q] += c.area * c.centroid;
      if (c.area > s.owner_area[q]) {
        s.owner_area[q] = c.area;
        s.owner[q] = std::uint32_t(i);
        s.owner_centroid[q] = c.centroid;
      }
    });
  return s;
}

// The slots in texel order (the order of the samples downstream), and the map to them.
void sort_slots_by_texel(coverage_slots& s) {
  const std::size_t count = s.texel.size();
  std::vector<std::uint32_t> order(count);
  for (std::size_t q = 0; q < count; ++q) order[q] = std::uint32_t(q);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return s.texel[a] < s.texel[b]; });
  const auto permute = [&](auto& v) {
    std::remove_reference_t<decltype(v)> out(count);
    for (std::size_t n = 0; n < count; ++n) out[n] = v[order[n]];
    v = std::move(out);
  };
  permute(s.texel);
  permute(s.sum_area);
  permute(s.owner_area);
  permute(s.sum_centroid);
  permute(s.owner_centroid);
  permute(s.owner);
  for (std::size_t n = 0; n < count; ++n) s.slot_of[s.texel[n]] = std::uint32_t(n);
}

// Each covered texel's combined centroid (the area-weighted mean of its clipped pieces); the
// sums are released.
std::vector<glm::dvec2> combined_centroids(coverage_slots& s) {
  std::vector<glm::dvec2> centroid(s.texel.size());
  for (std::size_t n = 0; n < centroid.size(); ++n) centroid[n] = s.sum_centroid[n] / s.sum_area[n];
  std::vector<glm::dvec2>().swap(s.sum_centroid);
  return centroid;
}

// Pass B: the triangle the combined centroid is mapped through: the owner if it contains it,
// else the covering triangle with the largest area that contains it (ties: lower index); none
// where no covering triangle contains it. The texel-to-slot map is released.
std::vector<std::uint32_t> through_triangles(const std::vector<tri_data>& tris, int width, int height, coverage_slots& s,
                                             const std::vector<glm::dvec2>& centroid) {
  constexpr std::uint32_t none = lightmap_samples::no_triangle;
  const double eps = 1e-9;
  std::vector<std::uint32_t> through(s.texel.size(), none);
  std::vector<double> through_area(s.texel.size(), 0.0);
  for (std::size_t i = 0; i < tris.size(); ++i)
    for_each_texel_in_bounds(tris[i], width, height, [&](int x, int y, std::size_t k) {
      const std::uint32_t q = s.slot_of[k];
      if (q == coverage_slots::no_slot || through[q] == s.owner[q]) return;
      double b1, b2;
      if (!barycentric(tris[i].t, centroid[q], b1, b2) || b1 < -eps || b2 < -eps || b1 + b2 > 1.0 + eps) return;
      const clip_d c = clip_texel(tris[i].t, x, y);
      if (!(c.area > 0.0)) return;
      if (std::uint32_t(i) == s.owner[q] || through[q] == none || c.area > through_area[q]) {
        through[q] = std::uint32_t(i);
        through_area[q] = c.area;
      }
    });
  std::vector<std::uint32_t>().swap(s.slot_of);
  return through;
}

// The sample of covered texel n: the point of triangle ti at texel-unit position q (clamped into
// the triangle), its interpolated normal (or the face's), texel size and lightmap tangent frame.
void set_sample(const bake_input& input, const tri_data& t, std::uint32_t ti, glm::dvec2 q, std::size_t n, sparse_samples& s) {
  const scene_desc& d = input.scene;
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
  s.centroid[n] = glm::vec2(float(q.x / s.width), float(q.y / s.height));
  s.position[n] = glm::vec3(b0 * p0 + b1 * p1 + b2 * p2);
  s.normal[n] = glm::vec3(nrm);
  s.texel_world_size[n] = float(std::sqrt(t.area3 / t.uv_area));
  const glm::vec3 tp[3] = {d.positions[idx[0]], d.positions[idx[1]], d.positions[idx[2]]};
  const glm::vec2 tuv[3] = {d.lightmap_uvs[idx[0]], d.lightmap_uvs[idx[1]], d.lightmap_uvs[idx[2]]};
  const frame f = lightmap_tangent_frame(tp, tuv, s.normal[n]);
  s.tangent[n] = f.t;
  s.bitangent[n] = f.b;
}

// The samples of the covered texels: coverage, owner and, through each texel's triangle (the
// owner's own centroid where the combined centroid lies on no covering triangle), its point.
void make_samples(const bake_input& input, const std::vector<tri_data>& tris, int width, int height, coverage_slots& slots,
                  const std::vector<glm::dvec2>& centroid, const std::vector<std::uint32_t>& through, sparse_samples& s) {
  constexpr std::uint32_t none = lightmap_samples::no_triangle;
  const std::size_t count = slots.texel.size();
  s.width = width;
  s.height = height;
  s.texel = std::move(slots.texel);
  s.coverage.resize(count);
  s.owner = std::move(slots.owner);
  s.sample_triangle.resize(count);
  s.centroid.resize(count);
  s.position.resize(count);
  s.normal.resize(count);
  s.texel_world_size.resize(count);
  s.tangent.resize(count);
  s.bitangent.resize(count);
  for (std::size_t n = 0; n < count; ++n) {
    s.coverage[n] = float(std::min(1.0, slots.sum_area[n]));
    if (slots.sum_area[n] > 1.001) ++s.overlapping_texels;
    std::uint32_t ti = through[n];
    glm::dvec2 q = centroid[n];
    if (ti == none) {  // the combined centroid lies on no covering triangle: the owner's own centroid
      ti = s.owner[n];
      q = slots.owner_centroid[n];
    }
    set_sample(input, tris[ti], ti, q, n, s);
  }
}

}  // namespace

sparse_samples compute_sparse_samples(const bake_input& input, int width, int height, bool strict, const char* who) {
  check_size(who, width, height);
  sparse_samples s;
  const std::vector<tri_data> tris = triangles_in_texels(who, input.scene, width, height, strict, s);
  coverage_slots slots = accumulate_coverage(who, tris, width, height);
  sort_slots_by_texel(slots);
  const std::vector<glm::dvec2> centroid = combined_centroids(slots);
  const std::vector<std::uint32_t> through = through_triangles(tris, width, height, slots, centroid);
  make_samples(input, tris, width, height, slots, centroid, through, s);
  return s;
}

}  // namespace bake_detail

texel_clip clip_triangle_to_texel(const glm::vec2& a, const glm::vec2& b, const glm::vec2& c, int x, int y) noexcept {
  const glm::dvec2 t[3] = {glm::dvec2(a), glm::dvec2(b), glm::dvec2(c)};
  const bake_detail::clip_d r = bake_detail::clip_texel(t, x, y);
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

lightmap_samples compute_lightmap_samples(const bake_input& input, int width, int height) {
  const char* who = "compute_lightmap_samples";
  bake_detail::check_size(who, width, height);
  bake_detail::check_input(who, input);
  bake_detail::clamped_input checked;
  bake_detail::clamp_lightmap_uvs(who, input, checked);
  const bake_detail::sparse_samples sp = bake_detail::compute_sparse_samples(checked.input, width, height, false, who);
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
  s.degenerate_triangles = sp.degenerate_triangles;
  s.no_uv_area_triangles = sp.no_uv_area_triangles;
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

}  // namespace hemilight
