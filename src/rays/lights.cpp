// Lights (lights.hpp): validation, closed-form unoccluded irradiance, and visibility from
// stratified shadow rays.
#include "hemilight/lights.hpp"

#include "hemilight/error.hpp"
#include "hemilight/geometry.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <unordered_map>
#include <array>

namespace hemilight {

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr float half_pi_f = 1.57079632679489662f;
constexpr int max_penumbra_samples = 65536;

std::string number(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  return buf;
}

std::string field(const char* array, std::size_t i, const char* name) {
  return std::string(array) + "[" + std::to_string(i) + "]." + name;
}

// v scaled by its largest |component| first, then normalised: works for subnormal and huge
// finite vectors alike. Returns 0 for a zero vector.
glm::vec3 normalize_robust(const glm::vec3& v) noexcept {
  const float m = std::max(std::fabs(v.x), std::max(std::fabs(v.y), std::fabs(v.z)));
  if (!(m > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 s = v / m;
  return s / std::sqrt(glm::dot(s, s));
}

void check_finite(const char* array, std::size_t i, const char* name, float v) {
  if (!std::isfinite(v)) throw_invalid_argument(field(array, i, name) + " is " + (std::isnan(v) ? "nan" : number(v)));
}

void check_finite(const char* array, std::size_t i, const char* name, const glm::vec3& v, const char* axes) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(v[c]))
      throw_invalid_argument(field(array, i, name) + "." + axes[c] + " is " + (std::isnan(v[c]) ? "nan" : number(v[c])));
}

// The cone of directions of half-angle a (sin^2 a = sin2a) around an axis at angle theta from the
// normal (cos theta = c): integral of max(0, cos) over the cone, i.e. E / L (see lights.hpp).
double cone_factor(double c, double sin2a) noexcept {
  if (sin2a >= 1.0 - 1e-12) return 0.5 * pi * (1.0 + c);  // a = pi/2: a half-space (a lune above the horizon)
  if (c * c >= sin2a) return c > 0.0 ? pi * sin2a * c : 0.0;  // fully above or fully below the horizon
  const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
  const double x = std::sqrt(1.0 / sin2a - 1.0);
  const double y = std::clamp(-x * c / s, -1.0, 1.0);
  const double sq = s * std::sqrt(std::max(0.0, 1.0 - y * y));
  return std::max(0.0, (c * std::acos(y) - x * sq) * sin2a + std::atan(sq / x));
}

// The rect clipped to p's upper half-space and Lambert's formula on it.
struct rect_form {
  double e_over_l = 0.0;       // E / L
  glm::dvec3 phi{0.0};         // sum of angle * unit edge normal (towards the light): vector irradiance / (L / 2)
  glm::dvec3 centroid{0.0};    // vertex centroid of the clipped polygon, relative to p
  bool any = false;
};

rect_form rect_closed_form(const light_set::prepared& L, const glm::vec3& p, const glm::vec3& n) noexcept {
  rect_form out;
  const glm::dvec3 c(L.l.position), nl(L.l.direction), t(L.l.tangent), b(L.bitangent), pd(p), nd(n);
  if (!(glm::dot(pd - c, nl) > 0.0)) return out;  // behind the emitting side (or in its plane)
  const double hw = 0.5 * double(L.l.width), hh = 0.5 * double(L.l.height);
  const glm::dvec3 q[4] = {c - hw * t - hh * b - pd, c + hw * t - hh * b - pd, c + hw * t + hh * b - pd,
                           c - hw * t + hh * b - pd};
  // Sutherland-Hodgman against dot(v, n) >= 0: at most five vertices.
  glm::dvec3 poly[5];
  int m = 0;
  for (int i = 0; i < 4; ++i) {
    const glm::dvec3& a = q[i];
    const glm::dvec3& e = q[(i + 1) % 4];
    const double da = glm::dot(a, nd), de = glm::dot(e, nd);
    if (da >= 0.0) poly[m++] = a;
    if ((da >= 0.0) != (de >= 0.0)) poly[m++] = a + (e - a) * (da / (da - de));
  }
  if (m < 3) return out;
  glm::dvec3 sum(0.0), centroid(0.0);
  for (int i = 0; i < m; ++i) {
    const glm::dvec3 a = glm::normalize(poly[i]), e = glm::normalize(poly[(i + 1) % m]);
    const glm::dvec3 x = glm::cross(a, e);
    const double len = glm::length(x);
    if (len > 0.0) sum += std::atan2(len, glm::dot(a, e)) * (x / len);
    centroid += poly[i];
  }
  centroid /= double(m);
  if (glm::dot(sum, centroid) < 0.0) sum = -sum;
  out.phi = sum;
  out.e_over_l = 0.5 * std::fabs(glm::dot(nd, sum));
  out.centroid = centroid;
  out.any = out.e_over_l > 0.0;
  return out;
}

float spot_factor(const light_set::prepared& L, const glm::vec3& to_point_unit) noexcept {
  const float cd = glm::dot(L.l.direction, to_point_unit);
  const float x = std::clamp(cd * L.spot_scale + L.spot_offset, 0.0f, 1.0f);
  return x * x;
}

// ---- sample patterns ------------------------------------------------------------------------------

std::uint64_t mix64(std::uint64_t z) noexcept {  // splitmix64's finaliser
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

std::uint64_t point_seed(const glm::vec3& p, const glm::vec3& n, std::size_t index) noexcept {
  std::uint32_t bits[6];
  std::memcpy(bits, &p, sizeof(float) * 3);
  std::memcpy(bits + 3, &n, sizeof(float) * 3);
  std::uint64_t h = mix64(0x9e3779b97f4a7c15ull + static_cast<std::uint64_t>(index));
  for (std::uint32_t b : bits) h = mix64(h ^ b);
  return h;
}

std::uint32_t reverse_bits(std::uint32_t x) noexcept {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// Sample k of the (0, 2)-sequence (van der Corput, second Sobol dimension; Kollig and Keller
// 2002) with the digital shift (s0, s1), in [0, 1)^2.
glm::vec2 sequence_sample(std::uint32_t k, std::uint32_t s0, std::uint32_t s1) noexcept {
  const std::uint32_t x = reverse_bits(k) ^ s0;
  std::uint32_t y = s1;
  for (std::uint32_t v = 1u << 31; k != 0; k >>= 1, v ^= v >> 1)
    if (k & 1u) y ^= v;
  return {static_cast<float>(x >> 8) * 0x1p-24f, static_cast<float>(y >> 8) * 0x1p-24f};
}

// Direction in the cone of half-angle a (1 - cos a = h_max) around the frame's n, equal-area.
glm::vec3 cone_direction(const frame& f, float h_max, const glm::vec2& u) noexcept {
  const float h = u.x * h_max;
  const float cos_g = 1.0f - h, sin_g = std::sqrt(std::max(0.0f, h * (2.0f - h)));
  const float phi = 6.28318530717958648f * u.y;
  return glm::normalize(f.to_world({sin_g * std::cos(phi), sin_g * std::sin(phi), cos_g}));
}

// Distance along unit w from o to the sphere (centre c, radius r); the closest approach if the
// ray misses it (rounding at the rim).
float sphere_distance(const glm::vec3& o, const glm::vec3& w, const glm::vec3& c, float r) noexcept {
  const glm::vec3 oc = c - o;
  const float b = glm::dot(oc, w);
  const glm::vec3 perp = oc - b * w;
  const float disc = r * r - glm::dot(perp, perp);
  return disc > 0.0f ? b - std::sqrt(disc) : b;
}

// The adaptive estimator of lights.hpp. sample(u, probe) maps u in [0, 1]^2 to a point of the
// light's extent (rects: the rectangle; cones: x = the cap's equal-area radius, 1 at the rim,
// y = the angle) and fills the probe: its weight (0: below the horizon, not traced) and either
// the shadow ray that decides its visibility or the visibility itself. The estimator traces the
// probes' rays in batches (occluded_many: one origin, Embree packets).
struct probe {
  float w = 0.0f, rw = 0.0f;  // weight and radiance weight
  glm::vec3 d{0.0f};          // unit direction (for the mean direction)
  glm::vec3 ray{0.0f};        // shadow ray direction, when `trace`
  float t_max = 0.0f;
  bool trace = false;         // visibility = transmittance(o, ray, t_max) (!occluded(...) without see-through triangles)
  bool visible = false;       // the visibility when not traced
};

struct visibility_result {
  glm::vec3 visibility{0.0f};  // per channel: translucent surfaces tint it (transmittance())
  glm::vec3 direction{0.0f};  // sum of V * radiance weight * direction (not normalised)
  bool any_traced = false;
};

// The outline probes in the unit square: a rect's corners and edge midpoints, or eight points
// on a cone's rim (inset by 1e-4 so that rounding keeps them on the light).
struct outline {
  glm::vec2 points[8];
};

constexpr float inset = 1e-4f;
constexpr outline rect_outline{{{inset, inset}, {0.5f, inset}, {1.0f - inset, inset}, {1.0f - inset, 0.5f},
                                {1.0f - inset, 1.0f - inset}, {0.5f, 1.0f - inset}, {inset, 1.0f - inset}, {inset, 0.5f}}};
constexpr outline cone_outline{{{1.0f - inset, 0.0625f}, {1.0f - inset, 0.1875f}, {1.0f - inset, 0.3125f},
                                {1.0f - inset, 0.4375f}, {1.0f - inset, 0.5625f}, {1.0f - inset, 0.6875f},
                                {1.0f - inset, 0.8125f}, {1.0f - inset, 0.9375f}}};

// The scalar visibility of a per-channel one: their mean (exactly the value when all agree).
float mean_visibility(const glm::vec3& v) noexcept {
  return v.x == v.y && v.y == v.z ? v.x : (v.x + v.y + v.z) / 3.0f;
}

template <class Sample>
visibility_result estimate(const scene& sc, const glm::vec3& origin, const direct_options& o, std::uint64_t seed,
                           const outline& edge, Sample&& sample) {
  const auto s0 = static_cast<std::uint32_t>(seed), s1 = static_cast<std::uint32_t>(seed >> 32);
  double sum_w = 0.0;
  glm::dvec3 sum_wv(0.0);
  glm::dvec3 dir(0.0);
  int traced = 0;
  bool uniform = true;  // every probe so far saw the same visibility
  glm::vec3 first(0.0f);
  constexpr int chunk = 16;
  probe pr[chunk];
  glm::vec3 rays[chunk];
  float t_max[chunk];
  bool hit[chunk];
  glm::vec3 through[chunk];
  const bool see_through = !sc.see_through_triangles().empty();
  // Samples [first, last) of the sequence "outline points (0-7), then the (0, 2)-sequence": each
  // chunk's probes first, their shadow rays in one batch, then accumulated in order.
  const auto run = [&](int first_sample, int last) {
    for (int base = first_sample; base < last; base += chunk) {
      const int n = std::min(chunk, last - base);
      int m = 0;
      for (int j = 0; j < n; ++j) {
        const int k = base + j;
        pr[j] = probe{};
        sample(k < 8 ? edge.points[k] : sequence_sample(static_cast<std::uint32_t>(k - 8), s0, s1), pr[j]);
        if (pr[j].w > 0.0f && pr[j].trace) {
          rays[m] = pr[j].ray;
          t_max[m] = pr[j].t_max;
          ++m;
        }
      }
      if (see_through) {
        for (int j = 0; j < m; ++j) through[j] = transmittance(sc, origin, rays[j], t_max[j]);
      } else {
        occluded_many(sc, origin, rays, t_max, static_cast<std::size_t>(m), hit);
        for (int j = 0; j < m; ++j) through[j] = glm::vec3(hit[j] ? 0.0f : 1.0f);
      }
      m = 0;
      for (int j = 0; j < n; ++j) {
        const probe& p = pr[j];
        if (!(p.w > 0.0f)) continue;
        const glm::vec3 v = p.trace ? through[m++] : glm::vec3(p.visible ? 1.0f : 0.0f);
        if (traced++ == 0) first = v;
        uniform = uniform && v == first;
        if (base + j < 8) continue;  // the outline decides only
        sum_w += double(p.w);
        sum_wv += double(p.w) * glm::dvec3(v);
        dir += double(p.rw) * double(mean_visibility(v)) * glm::dvec3(p.d);
      }
    }
  };
  // Probes: the outline (decides only; not part of the estimate, which it would bias towards the
  // edges) and the sequence's first probe_samples samples (kept).
  run(0, 8 + o.probe_samples);
  visibility_result r;
  if (traced > 0 && uniform && (first == glm::vec3(0.0f) || first == glm::vec3(1.0f) || see_through)) {
    // Every probe agrees (wholly lit, wholly shadowed, or behind the same panes): that is the answer.
    r.any_traced = true;
    r.visibility = first;
    r.direction = glm::vec3(dir);
    return r;
  }
  run(8 + o.probe_samples, 8 + o.penumbra_samples);
  r.any_traced = sum_w > 0.0;
  r.visibility = r.any_traced ? glm::vec3(sum_wv / sum_w) : glm::vec3(0.0f);
  r.direction = glm::vec3(dir);
  return r;
}

void check_options(const direct_options& o) {
  if (o.probe_samples < 0)
    throw_invalid_argument("direct_options: probe_samples = " + std::to_string(o.probe_samples) + " is negative");
  if (o.penumbra_samples < o.probe_samples || o.penumbra_samples > max_penumbra_samples)
    throw_invalid_argument("direct_options: penumbra_samples = " + std::to_string(o.penumbra_samples) +
                           " must be in [probe_samples = " + std::to_string(o.probe_samples) + ", " +
                           std::to_string(max_penumbra_samples) + "]");
  if (!(o.offset_scale >= 0.0f) || !std::isfinite(o.offset_scale))
    throw_invalid_argument("direct_options: offset_scale = " + number(o.offset_scale) + " must be finite and >= 0");
}

float ray_offset(const scene& s, const glm::vec3& p, const direct_options& o) noexcept {
  const float m = std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z)));
  return o.offset_scale * s.size() + 0x1p-18f * m;
}

// What a shadow ray along d up to t_max lets through: 0 or 1, or per channel through translucent
// surfaces (transmittance(); the plain any-hit query when the scene has no see-through triangle).
glm::vec3 shadow_ray(const scene& s, const glm::vec3& o, const glm::vec3& d, float t_max) noexcept {
  if (!s.see_through_triangles().empty()) return transmittance(s, o, d, t_max);
  return glm::vec3(occluded(s, o, d, t_max) ? 0.0f : 1.0f);
}

// A shadow ray from o to the point q, stopping `off` short of q: what arrives (shadow_ray).
glm::vec3 reaches(const scene& s, const glm::vec3& o, const glm::vec3& q, float off) noexcept {
  const glm::vec3 d = q - o;
  const float len = glm::length(d);
  if (!(len > off)) return glm::vec3(1.0f);
  return shadow_ray(s, o, d, 1.0f - off / len);
}

// The unoccluded closed form with the geometry the sampling needs.
struct light_geometry {
  glm::vec3 e{0.0f};       // unoccluded irradiance
  glm::vec3 axis{0.0f};    // cones: unit direction to the centre; hard lights: to the light
  float distance = 0.0f;   // point, spot: to the centre
  float sin2a = 0.0f;      // cones: sin^2 of the half-angle (0: hard)
  bool inside = false;     // p inside a sphere light
  rect_form rect;          // rect
};

light_geometry closed_form(const light_set::prepared& L, const glm::vec3& p, const glm::vec3& n) noexcept {
  light_geometry g;
  switch (L.l.type) {
    case light_type::directional: {
      g.axis = -L.l.direction;
      const float c = glm::dot(n, g.axis);
      if (L.l.radius == 0.0f) {
        g.e = L.l.color * std::max(0.0f, c);
      } else {
        g.sin2a = L.sin2_radius;
        g.e = L.l.color * static_cast<float>(cone_factor(double(c), double(g.sin2a)) / (pi * double(g.sin2a)));
      }
      break;
    }
    case light_type::point:
    case light_type::spot: {
      const glm::vec3 v = L.l.position - p;
      const float d = glm::length(v);
      if (!(d > 0.0f)) break;  // at the light's centre: nothing (the closed form is singular)
      g.distance = d;
      g.axis = v / d;
      const float spot = L.l.type == light_type::spot ? spot_factor(L, -g.axis) : 1.0f;
      if (spot == 0.0f) break;
      const float c = glm::dot(n, g.axis);
      if (L.l.radius == 0.0f) {
        g.e = L.l.color * (spot * std::max(0.0f, c) / (d * d));
      } else {
        const double r = double(L.l.radius);
        const double sin2 = std::min(1.0, (r * r) / (double(d) * double(d)));
        g.inside = d <= L.l.radius;
        g.sin2a = static_cast<float>(sin2);
        g.e = L.l.color * static_cast<float>(double(spot) * cone_factor(double(c), sin2) / (pi * r * r));
      }
      break;
    }
    case light_type::rect: {
      g.rect = rect_closed_form(L, p, n);
      g.e = L.l.color * static_cast<float>(g.rect.e_over_l);
      break;
    }
  }
  if (!(g.e.x > 0.0f || g.e.y > 0.0f || g.e.z > 0.0f)) g.e = glm::vec3(0.0f);
  return g;
}

}  // namespace

// ---- validation ---------------------------------------------------------------------------------

void validate_lights(const light* lights, std::size_t count, const char* array) {
  if (count > 0 && !lights) throw_invalid_argument(std::string(array) + " is null but count is " + std::to_string(count));
  for (std::size_t i = 0; i < count; ++i) {
    const light& l = lights[i];
    const int type = static_cast<int>(l.type);
    if (type < 0 || type > 3) throw_invalid_argument(field(array, i, "type") + " = " + std::to_string(type) + " is unknown");
    check_finite(array, i, "color", l.color, "rgb");
    check_finite(array, i, "position", l.position, "xyz");
    for (int c = 0; c < 3; ++c)
      if (std::fabs(l.position[c]) > max_coordinate)
        throw_invalid_argument(field(array, i, "position") + "." + "xyz"[c] + " = " + number(l.position[c]) +
                               " is beyond 1e18 (max_coordinate)");
    check_finite(array, i, "direction", l.direction, "xyz");
    check_finite(array, i, "tangent", l.tangent, "xyz");
    check_finite(array, i, "width", l.width);
    check_finite(array, i, "height", l.height);
    check_finite(array, i, "radius", l.radius);
    check_finite(array, i, "spot_inner", l.spot_inner);
    check_finite(array, i, "spot_outer", l.spot_outer);
    for (int c = 0; c < 3; ++c)
      if (l.color[c] < 0.0f)
        throw_invalid_argument(field(array, i, "color") + "." + "rgb"[c] + " = " + number(l.color[c]) + " is negative");
      else if (l.color[c] > max_radiance)
        throw_invalid_argument(field(array, i, "color") + "." + "rgb"[c] + " = " + number(l.color[c]) +
                               " is over 1e30 (max_radiance: sums of it must stay finite)");
    if (l.type != light_type::point && normalize_robust(l.direction) == glm::vec3(0.0f))
      throw_invalid_argument(field(array, i, "direction") + " is zero");
    if (l.type != light_type::rect && l.radius < 0.0f)
      throw_invalid_argument(field(array, i, "radius") + " = " + number(l.radius) + " is negative");
    if (l.type == light_type::directional && l.radius > half_pi_f)
      throw_invalid_argument(field(array, i, "radius") + " = " + number(l.radius) + " is past pi/2");
    if (l.type == light_type::spot) {
      if (l.spot_inner < 0.0f)
        throw_invalid_argument(field(array, i, "spot_inner") + " = " + number(l.spot_inner) + " is negative");
      if (l.spot_outer > half_pi_f)
        throw_invalid_argument(field(array, i, "spot_outer") + " = " + number(l.spot_outer) + " is past pi/2");
      if (l.spot_inner > l.spot_outer)
        throw_invalid_argument(field(array, i, "spot_inner") + " = " + number(l.spot_inner) + " is greater than spot_outer = " +
                               number(l.spot_outer));
    }
    if (l.type == light_type::rect) {
      if (!(l.width > 0.0f)) throw_invalid_argument(field(array, i, "width") + " = " + number(l.width) + " is not positive");
      if (!(l.height > 0.0f)) throw_invalid_argument(field(array, i, "height") + " = " + number(l.height) + " is not positive");
      const glm::vec3 t = normalize_robust(l.tangent), nl = normalize_robust(l.direction);
      if (t == glm::vec3(0.0f)) throw_invalid_argument(field(array, i, "tangent") + " is zero");
      // |t x n| = sin of the angle between them: within 1e-3 rad of parallel is rejected.
      if (glm::length(glm::cross(t, nl)) < 1e-3f)
        throw_invalid_argument(field(array, i, "tangent") + " is parallel to direction (the rect's normal)");
    }
  }
}

light_set::light_set(const light* lights, std::size_t count) {
  validate_lights(lights, count);
  lights_.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    prepared& p = lights_[i];
    p.l = lights[i];
    p.l.direction = normalize_robust(p.l.direction);
    if (p.l.type == light_type::rect) {
      const glm::vec3 t = normalize_robust(p.l.tangent);
      p.l.tangent = normalize_robust(t - glm::dot(t, p.l.direction) * p.l.direction);
      p.bitangent = glm::cross(p.l.direction, p.l.tangent);
    } else {
      p.l.tangent = normalize_robust(p.l.tangent);
    }
    if (p.l.type == light_type::directional && p.l.radius > 0.0f) {
      const double r = double(p.l.radius), sh = std::sin(0.5 * r);
      p.sin2_radius = static_cast<float>(std::sin(r) * std::sin(r));
      p.one_minus_cos_radius = static_cast<float>(2.0 * sh * sh);
    }
    if (p.l.type == light_type::spot) {
      const float ci = std::cos(p.l.spot_inner), co = std::cos(p.l.spot_outer);
      p.spot_scale = 1.0f / std::max(0.001f, ci - co);
      p.spot_offset = -co * p.spot_scale;
    }
  }
}

// ---- evaluation ---------------------------------------------------------------------------------

glm::vec3 unoccluded_irradiance(const light_set& lights, std::size_t i, const glm::vec3& p, const glm::vec3& n) noexcept {
  assert(i < lights.size());
  assert(std::fabs(glm::length(n) - 1.0f) < 1e-3f);
  return closed_form(lights.prepared_light(i), p, n).e;
}

namespace {
light_sample direct_light_unchecked(const scene& s, const light_set& lights, std::size_t i, const glm::vec3& p,
                                    const glm::vec3& n, const direct_options& options);
}  // namespace

light_sample direct_light(const scene& s, const light_set& lights, std::size_t i, const glm::vec3& p, const glm::vec3& n,
                          const direct_options& options) {
  check_options(options);
  return direct_light_unchecked(s, lights, i, p, n, options);
}

namespace {

// direct_light_unchecked's visibility of a rect light over its clipped outline (soft shadows),
// and where the closed form's direction holds, that direction in out.direction.
visibility_result rect_visibility(const scene& s, const light_set::prepared& L, const light_geometry& g,
                                  const glm::vec3& p, const glm::vec3& n, const glm::vec3& o, float off,
                                  std::uint64_t seed, const direct_options& options, light_sample& out,
                                  bool& closed_direction) {
  const bool shadows = L.l.casts_shadows;
  visibility_result v;
  const glm::vec3 c = L.l.position, t = L.l.tangent * L.l.width, b = L.bitangent * L.l.height, nl = L.l.direction;
  v = estimate(s, o, options, seed, rect_outline, [&](const glm::vec2& u, probe& pb) {
    const glm::vec3 q = c + (u.x - 0.5f) * t + (u.y - 0.5f) * b;
    const glm::vec3 to = q - o;
    const float d2 = glm::dot(to, to);
    if (!(d2 > 0.0f)) return;
    pb.d = to / std::sqrt(d2);
    const float cos_r = glm::dot(n, pb.d), cos_l = -glm::dot(nl, pb.d);
    if (!(cos_r > 0.0f) || !(cos_l > 0.0f)) return;
    pb.rw = cos_l / d2;
    pb.w = cos_r * pb.rw;
    pb.visible = true;
    if (shadows) {  // reaches(s, o, q, off), traced by the estimator
      const float len = glm::length(to);
      if (len > off) {
        pb.trace = true;
        pb.ray = to;
        pb.t_max = 1.0f - off / len;
      }
    }
  });
  closed_direction = v.visibility == glm::vec3(1.0f);
  if (!v.any_traced) {  // a sliver above the horizon: one ray to the clipped polygon's centroid
    const glm::vec3 q = p + glm::vec3(g.rect.centroid);
    v.visibility = shadows ? reaches(s, o, q, off) : glm::vec3(1.0f);
    closed_direction = v.visibility == glm::vec3(1.0f);
  }
  if (closed_direction) out.direction = glm::vec3(glm::normalize(g.rect.phi));
  return v;
}

// The same for a cone: the sun's disc, or a sphere light seen from p.
visibility_result cone_visibility(const scene& s, const light_set::prepared& L, const light_geometry& g,
                                  const glm::vec3& n, const glm::vec3& o, float off, std::uint64_t seed,
                                  const direct_options& options, light_sample& out, bool& closed_direction) {
  const bool shadows = L.l.casts_shadows;
  visibility_result v;
  // Cones: the sun's disc, or the sphere seen from p.
  const bool sun = L.l.type == light_type::directional;
  const float h_max = sun ? L.one_minus_cos_radius
                          : static_cast<float>(double(g.sin2a) / (1.0 + std::sqrt(std::max(0.0, 1.0 - double(g.sin2a)))));
  const float cos_axis = glm::dot(n, g.axis);
  const bool above = double(cos_axis) > 0.0 && double(cos_axis) * double(cos_axis) >= double(g.sin2a);
  if (g.inside) {
    // p inside a sphere light: no ray can leave the light; it is taken as visible.
    v.visibility = glm::vec3(1.0f);
    v.any_traced = true;
    out.direction = g.axis;
    closed_direction = true;
  } else {
    const frame f = make_frame(g.axis);
    const float r = L.l.radius;
    v = estimate(s, o, options, seed, cone_outline, [&](const glm::vec2& u, probe& pb) {
      pb.d = cone_direction(f, h_max, u);
      const float cos_r = glm::dot(n, pb.d);
      if (!(cos_r > 0.0f)) return;
      pb.w = cos_r;
      pb.rw = 1.0f;
      pb.visible = true;
      if (!shadows) return;
      if (sun) {
        pb.trace = true;
        pb.ray = pb.d;
        pb.t_max = std::numeric_limits<float>::infinity();
      } else {
        const float t = sphere_distance(o, pb.d, L.l.position, r) - off;
        if (t > 0.0f) {
          pb.trace = true;
          pb.ray = pb.d;
          pb.t_max = t;
        }
      }
    });
    if (!v.any_traced) {  // a sliver above the horizon: one ray to the cone's point nearest the normal
      const glm::vec3 across = g.axis - cos_axis * n;
      const float len = glm::length(across);
      glm::vec3 d = g.axis;
      if (len > 0.0f) {
        const float theta = std::acos(std::clamp(cos_axis, -1.0f, 1.0f));
        const float a = std::asin(std::sqrt(std::min(1.0f, g.sin2a)));
        const float gamma = std::max(0.0f, theta - 0.999f * a);
        d = std::cos(gamma) * n + std::sin(gamma) * (across / len);
      }
      glm::vec3 visible(1.0f);
      if (shadows) {
        if (sun) {
          visible = shadow_ray(s, o, d, std::numeric_limits<float>::infinity());
        } else {
          const float t = sphere_distance(o, d, L.l.position, r) - off;
          if (t > 0.0f) visible = shadow_ray(s, o, d, t);
        }
      }
      v.visibility = visible;
      v.direction = visible != glm::vec3(0.0f) ? d : glm::vec3(0.0f);
    }
    closed_direction = above && v.visibility == glm::vec3(1.0f);
    if (closed_direction) out.direction = g.axis;
  }
  return v;
}

// direct_light with the options already checked (direct_irradiance checks them once per point,
// not once per light).
light_sample direct_light_unchecked(const scene& s, const light_set& lights, std::size_t i, const glm::vec3& p,
                                    const glm::vec3& n, const direct_options& options) {
  assert(i < lights.size());
  assert(std::fabs(glm::length(n) - 1.0f) < 1e-3f);
  const light_set::prepared& L = lights.prepared_light(i);
  const light_geometry g = closed_form(L, p, n);
  light_sample out;
  out.unoccluded = g.e;
  if (g.e == glm::vec3(0.0f)) return out;
  const bool shadows = L.l.casts_shadows;
  const float off = ray_offset(s, p, options);
  const glm::vec3 o = p + off * n;
  const bool hard = L.l.type != light_type::rect && L.l.radius == 0.0f;
  if (hard) {
    glm::vec3 visible(1.0f);
    if (shadows) {
      if (L.l.type == light_type::directional)
        visible = shadow_ray(s, o, g.axis, std::numeric_limits<float>::infinity());
      else
        visible = reaches(s, o, L.l.position, off);
    }
    out.visibility_rgb = visible;
    out.visibility = mean_visibility(visible);
    out.irradiance = g.e * visible;
    out.direction = out.irradiance != glm::vec3(0.0f) ? g.axis : glm::vec3(0.0f);
    return out;
  }
  const std::uint64_t seed = point_seed(p, n, i);
  visibility_result v;
  bool closed_direction = false;  // the closed form's direction is right (fully visible, fully above)
  if (L.l.type == light_type::rect)
    v = rect_visibility(s, L, g, p, n, o, off, seed, options, out, closed_direction);
  else
    v = cone_visibility(s, L, g, n, o, off, seed, options, out, closed_direction);
  out.visibility_rgb = v.visibility;
  out.visibility = mean_visibility(v.visibility);
  out.irradiance = g.e * v.visibility;
  if (!closed_direction) {
    const float len = glm::length(v.direction);
    out.direction = len > 0.0f && out.visibility > 0.0f ? v.direction / len : glm::vec3(0.0f);
  }
  if (out.irradiance == glm::vec3(0.0f)) out.direction = glm::vec3(0.0f);
  return out;
}

}  // namespace

glm::vec3 direct_irradiance(const scene& s, const light_set& lights, const glm::vec3& p, const glm::vec3& n,
                            const direct_options& options, light_sample* per_light) {
  check_options(options);
  glm::vec3 sum(0.0f);
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const light_sample ls = direct_light_unchecked(s, lights, i, p, n, options);
    sum += ls.irradiance;
    if (per_light) per_light[i] = ls;
  }
  return sum;
}

void validate_direct_options(const direct_options& options) { check_options(options); }

}  // namespace hemilight

namespace hemilight {

namespace {

// An edge by its two end positions' bits, smaller first: the same edge whatever the indices.
struct edge_key {
  std::array<std::uint32_t, 6> bits;
  bool operator==(const edge_key& o) const noexcept { return bits == o.bits; }
};
struct edge_key_hash {
  std::size_t operator()(const edge_key& k) const noexcept {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint32_t b : k.bits) h = (h ^ b) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};
edge_key key_of(const glm::vec3& a, const glm::vec3& b) {
  std::array<std::uint32_t, 3> ba, bb;
  std::memcpy(ba.data(), &a, sizeof(a));
  std::memcpy(bb.data(), &b, sizeof(b));
  if (bb < ba) std::swap(ba, bb);
  return {{ba[0], ba[1], ba[2], bb[0], bb[1], bb[2]}};
}

bool same_bits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }

// The RECT the two triangles t (corners p, q shared, r its own) and u (s its own) form, if they
// form a rectangle with diagonal p-q (see emissive_rects_to_lights).
bool rect_of(const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& r, const glm::dvec3& s, const glm::dvec3& normal_t,
             const glm::dvec3& normal_u, light& out) {
  const double diagonal = glm::length(q - p);
  if (!(diagonal > 0.0)) return false;
  const double tol = 1e-4 * diagonal;
  const glm::dvec3 u = p - r, v = q - r;  // the sides at r
  const double lu = glm::length(u), lv = glm::length(v);
  if (!(lu > tol) || !(lv > tol)) return false;
  if (std::fabs(glm::dot(u, v)) > tol * std::max(lu, lv)) return false;  // right angle at r
  if (glm::length(s - (p + q - r)) > tol) return false;                   // the fourth corner
  const double nt = glm::length(normal_t), nu = glm::length(normal_u);
  if (!(nt > 0.0) || !(nu > 0.0) || glm::dot(normal_t, normal_u) < (1.0 - 1e-6) * nt * nu) return false;  // same facing
  out.type = light_type::rect;
  out.position = glm::vec3(0.5 * (p + q));
  out.direction = glm::vec3(normal_t / nt);
  out.tangent = glm::vec3(u / lu);
  out.width = float(lu);
  out.height = float(lv);
  out.casts_shadows = true;
  return true;
}

}  // namespace

std::vector<light> emissive_rects_to_lights(scene_mesh& mesh) {
  std::vector<light> lights;
  const std::size_t triangles = std::min(mesh.triangle_count(), mesh.materials.size());
  const std::size_t vertices = mesh.positions.size();
  const auto corner = [&](std::size_t t, int k) { return mesh.positions[mesh.indices[3 * t + std::size_t(k)]]; };
  const auto candidate = [&](std::size_t t) {
    const material& m = mesh.materials[t];
    if (m.two_sided || m.emission == glm::vec3(0.0f)) return false;
    for (int k = 0; k < 3; ++k)
      if (mesh.indices[3 * t + std::size_t(k)] >= vertices) return false;
    return true;
  };
  // Step 1: the edges of the candidate triangles, each with the triangles that have it.
  std::unordered_map<edge_key, std::vector<std::uint32_t>, edge_key_hash> edges;
  for (std::size_t t = 0; t < triangles; ++t) {
    if (!candidate(t)) continue;
    for (int k = 0; k < 3; ++k) edges[key_of(corner(t, k), corner(t, (k + 1) % 3))].push_back(static_cast<std::uint32_t>(t));
  }
  // Step 2: greedy pairing in index order.
  std::vector<std::uint8_t> used(triangles, 0);
  for (std::size_t t = 0; t < triangles; ++t) {
    if (used[t] || !candidate(t)) continue;
    const glm::dvec3 a(corner(t, 0)), b(corner(t, 1)), c(corner(t, 2));
    const glm::dvec3 normal_t = glm::cross(b - a, c - a);
    for (int k = 0; k < 3 && !used[t]; ++k) {
      const glm::vec3 p = corner(t, k), q = corner(t, (k + 1) % 3), r = corner(t, (k + 2) % 3);
      for (const std::uint32_t u : edges[key_of(p, q)]) {
        if (u == t || used[u] || !same_bits(mesh.materials[u].emission, mesh.materials[t].emission)) continue;
        int own = -1;  // u's corner that is not on the shared edge
        for (int j = 0; j < 3; ++j)
          if (!same_bits(corner(u, j), p) && !same_bits(corner(u, j), q)) own = j;
        if (own < 0) continue;
        const glm::dvec3 ua(corner(u, 0)), ub(corner(u, 1)), uc(corner(u, 2));
        light l;
        if (!rect_of(glm::dvec3(p), glm::dvec3(q), glm::dvec3(r), glm::dvec3(corner(u, own)), normal_t,
                     glm::cross(ub - ua, uc - ua), l))
          continue;
        l.color = mesh.materials[t].emission;
        lights.push_back(l);
        used[t] = used[u] = 1;
        break;
      }
    }
  }
  // Step 3: the paired triangles stop emitting (the lights carry their light now).
  for (std::size_t t = 0; t < triangles; ++t)
    if (used[t]) mesh.materials[t].emission = glm::vec3(0.0f);
  return lights;
}

}  // namespace hemilight
