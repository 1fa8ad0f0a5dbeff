// Tests of lights.hpp against references that do not come from the library: closed forms
// written out here (I cos / d^2, the glTF spot falloff, the form factor of a parallel rectangle),
// Lambert's polygon formula of tests/raycast_reference.hpp, and direct numerical quadrature of
// L cos(theta) (cos(theta') / d^2) over the light's directions or area.
#include "hemilight/lights.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/reference_scenes.hpp"

#include "raycast_reference.hpp"
#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

using namespace hemilight;
using namespace hemilight::test;

namespace {

constexpr double pi = 3.14159265358979323846;

// A 40 x 40 m floor at z = 0 facing up (+z), the receiver of most tests: shadow rays start on it,
// so the ray origin offset is exercised everywhere.
scene_mesh floor_mesh() {
  scene_mesh m;
  m.add_quad({-20, -20, 0}, {20, -20, 0}, {20, 20, 0}, {-20, 20, 0}, material{});
  return m;
}

std::shared_ptr<const scene> make(const scene_mesh& m) { return scene::create(m.desc()); }

light point_light(glm::vec3 pos, float intensity, float radius = 0.0f) {
  light l;
  l.type = light_type::point;
  l.position = pos;
  l.color = glm::vec3(intensity, 0.5f * intensity, 0.25f * intensity);
  l.radius = radius;
  return l;
}

light rect_light(glm::vec3 centre, glm::vec3 normal, glm::vec3 tangent, float w, float h, float radiance) {
  light l;
  l.type = light_type::rect;
  l.position = centre;
  l.direction = normal;
  l.tangent = tangent;
  l.width = w;
  l.height = h;
  l.color = glm::vec3(radiance);
  return l;
}

// Irradiance at the origin (normal +z) of a cone of directions of uniform radiance 1, half-angle
// a, around the unit axis: midpoint quadrature over (gamma, phi) in the cone's own frame of
// integral of max(0, cos theta) sin(gamma) dgamma dphi. 800 x 1600 cells: error ~1e-5 relative
// (the horizon's kink costs O(h^2) per cut cell).
double cone_quadrature(const glm::dvec3& axis, double a) {
  const frame f = make_frame(glm::vec3(axis));
  const glm::dvec3 t(f.t), b(f.b), n(f.n);
  const int ng = 800, np = 1600;
  double sum = 0.0;
  for (int i = 0; i < ng; ++i) {
    const double g = (i + 0.5) * a / ng;
    for (int j = 0; j < np; ++j) {
      const double ph = (j + 0.5) * 2.0 * pi / np;
      const glm::dvec3 w = std::sin(g) * std::cos(ph) * t + std::sin(g) * std::sin(ph) * b + std::cos(g) * n;
      sum += std::max(0.0, w.z) * std::sin(g);
    }
  }
  return sum * (a / ng) * (2.0 * pi / np);
}

// Irradiance at p (normal +z) of a one-sided rectangle of radiance 1 (corners c +- u/2 +- v/2,
// emitting towards normal nl): midpoint quadrature of cos+ cos'+ / d^2 over its area, k x k cells.
double rect_quadrature(const glm::dvec3& p, const glm::dvec3& c, const glm::dvec3& u, const glm::dvec3& v,
                       const glm::dvec3& nl, int k) {
  double sum = 0.0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const glm::dvec3 q = c + ((i + 0.5) / k - 0.5) * u + ((j + 0.5) / k - 0.5) * v;
      const glm::dvec3 d = q - p;
      const double d2 = glm::dot(d, d), len = std::sqrt(d2);
      sum += std::max(0.0, d.z / len) * std::max(0.0, -glm::dot(nl, d) / len) / d2;
    }
  return sum * glm::length(glm::cross(u, v)) / (double(k) * k);
}

// The form factor of a parallel rectangle a x b with one corner straight above the point at
// height h (the classical closed form), times pi: E / L.
double parallel_corner_rect(double a, double b, double h) {
  const double x = a / h, y = b / h;
  return 0.5 * (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) +
                y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y)));
}

double rel(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

}  // namespace

TEST_CASE("lights: a hard point light over a plane is I cos / d^2", "[lights]") {
  const auto s = make(floor_mesh());
  const light l = point_light({0.3f, -0.2f, 2.0f}, 5.0f);
  const light_set set(&l, 1);
  for (float x : {-3.0f, -1.0f, 0.0f, 0.3f, 0.7f, 2.5f})
    for (float y : {-2.0f, 0.0f, 1.5f}) {
      const glm::dvec3 p(x, y, 0.0), d = glm::dvec3(l.position) - p;
      const double expected = 5.0 * (d.z / glm::length(d)) / glm::dot(d, d);
      const light_sample ls = direct_light(*s, set, 0, glm::vec3(p), {0, 0, 1});
      // 1e-3 (the tolerance for hard lights); float evaluation is good to ~1e-6.
      CHECK(rel(ls.irradiance.x, expected) < 1e-3);
      CHECK(rel(ls.irradiance.y, 0.5 * expected) < 1e-3);
      CHECK(ls.visibility == 1.0f);
      CHECK(glm::length(ls.direction - glm::vec3(glm::normalize(d))) < 1e-5f);
    }
  // Facing away: nothing, and no ray is needed.
  const light_sample away = direct_light(*s, set, 0, {0, 0, 0}, {0, 0, -1});
  CHECK(away.irradiance == glm::vec3(0.0f));
  CHECK(away.unoccluded == glm::vec3(0.0f));
}

TEST_CASE("lights: a spot light is the point light times glTF's falloff (inside inner, between, outside outer)",
          "[lights]") {
  const auto s = make(floor_mesh());
  light l = point_light({0.0f, 0.0f, 2.0f}, 4.0f);
  l.type = light_type::spot;
  l.direction = {0, 0, -1};
  l.spot_inner = 0.3f;
  l.spot_outer = 0.6f;
  const light_set set(&l, 1);
  const double ci = std::cos(0.3), co = std::cos(0.6);
  int inside = 0, between = 0, outside = 0;
  for (int k = 0; k <= 40; ++k) {
    const double angle = 0.9 * k / 40.0;  // angle from the axis, 0 .. 0.9 rad
    const glm::dvec3 p(2.0 * std::tan(angle), 0.0, 0.0), d = glm::dvec3(0, 0, 2) - p;
    const double point = 4.0 * (2.0 / glm::length(d)) / glm::dot(d, d);
    const double cd = std::cos(angle);
    const double x = std::clamp((cd - co) / std::max(0.001, ci - co), 0.0, 1.0);
    const double expected = point * x * x;
    const float e = direct_light(*s, set, 0, glm::vec3(p), {0, 0, 1}).irradiance.x;
    if (angle < 0.299) {
      ++inside;
      CHECK(rel(e, point) < 1e-3);  // full intensity inside the inner cone
    } else if (angle > 0.601) {
      ++outside;
      CHECK(e == 0.0f);  // exactly dark outside the outer cone
    } else {
      ++between;
      // the falloff's square makes the relative error twice the cosine's rounding (~1e-6 / x)
      CHECK(std::fabs(e - expected) < 1e-3 * point);
    }
  }
  CHECK(inside > 5);
  CHECK(between > 5);
  CHECK(outside > 5);
}

TEST_CASE("lights: the sun, hard and with an angular radius, against E cos and cone quadrature", "[lights]") {
  const auto s = make(floor_mesh());
  for (float radius : {0.0f, 0.00465f, 0.3f, 1.2f}) {
    light l;
    l.type = light_type::directional;
    l.color = glm::vec3(3.0f);
    l.radius = radius;
    for (double elevation : {1.5, 1.0, 0.5, 0.2, 0.05, -0.1}) {
      INFO("radius " << radius << " elevation " << elevation);
      const glm::dvec3 to_sun(std::cos(elevation), 0.0, std::sin(elevation));
      l.direction = glm::vec3(-to_sun);
      const light_set set(&l, 1);
      const glm::vec3 p(0.5f, 0.5f, 0.0f);
      const light_sample ls = direct_light(*s, set, 0, p, {0, 0, 1});
      const bool straddles = radius > 0.0f && std::fabs(elevation) < double(radius);
      if (!straddles) {
        // Fully above (or below) the horizon the disc gives exactly E cos theta: 1e-3 for the
        // hard sun (as for every hard light), 1e-3 too with a radius (the closed form is exact there).
        const double expected = 3.0 * std::max(0.0, std::sin(elevation));
        if (expected == 0.0)
          CHECK(ls.irradiance.x == 0.0f);
        else
          CHECK(rel(ls.irradiance.x, expected) < 1e-3);
      } else {
        // Across the horizon: the cone quadrature, radiance E / (pi sin^2 a); 1% (the
        // tolerance for lights with a radius; the quadrature is good to ~1e-5).
        const double l_sun = 3.0 / (pi * std::sin(radius) * std::sin(radius));
        const double expected = l_sun * cone_quadrature(to_sun, double(radius));
        CHECK(rel(ls.irradiance.x, expected) < 1e-2);
      }
    }
  }
}

TEST_CASE("lights: a sphere light equals the point above the horizon and the cone quadrature across it", "[lights]") {
  const auto s = make(scene_mesh{});  // no geometry: unoccluded
  const float r = 0.5f;
  const light l = point_light({0.0f, 0.0f, 0.0f}, 2.0f, r);
  const light_set set(&l, 1);
  for (double height : {3.0, 1.0, 0.6, 0.3, 0.0, -0.2, -0.45})
    for (double lateral : {0.0, 0.8, 2.0}) {
      const glm::dvec3 c(0.0), p(lateral, 0.0, -height);  // the light is `height` above p's plane
      const double d = glm::length(c - p);
      if (d <= double(r) * 1.001) continue;
      INFO("height " << height << " lateral " << lateral);
      const glm::dvec3 axis = (c - p) / d;
      const double a = std::asin(double(r) / d);
      const double lum = 2.0 / (pi * double(r) * double(r));
      const double expected = lum * cone_quadrature(axis, a);
      const float e = direct_light(*s, set, 0, glm::vec3(p), {0, 0, 1}).irradiance.x;
      if (expected < 1e-9) {
        CHECK(e == 0.0f);
        continue;
      }
      if (axis.z >= std::sin(a)) CHECK(rel(e, 2.0 * axis.z / (d * d)) < 1e-3);  // fully above: the point's I cos / d^2
      CHECK(rel(e, expected) < 1e-2);  // 1%: the tolerance for lights with a radius
    }
  // Inside the sphere: the limit of a half-space of radiance I / (pi r^2), E = pi L (1 + cos) / 2.
  const float inside = direct_light(*s, set, 0, {0.1f, 0.0f, 0.0f}, {0, 0, 1}).irradiance.x;
  CHECK(rel(inside, pi * 2.0 / (pi * 0.25) * 0.5 * (1.0 + 0.0)) < 1e-3);
}

TEST_CASE("lights: a RECT over a plane against the parallel-rectangle form factor and Lambert's formula", "[lights]") {
  const auto s = make(floor_mesh());
  // Parallel, 2 x 1 m at height 1.5, facing down; the point under one corner and under the centre.
  const light l = rect_light({1.0f, 0.5f, 1.5f}, {0, 0, -1}, {1, 0, 0}, 2.0f, 1.0f, 3.0f);
  const light_set set(&l, 1);
  const float corner = direct_light(*s, set, 0, {0, 0, 0}, {0, 0, 1}).irradiance.x;
  CHECK(rel(corner, 3.0 * parallel_corner_rect(2.0, 1.0, 1.5)) < 1e-3);  // 1e-3: hard-light bound (exact form)
  const float centre = direct_light(*s, set, 0, {1.0f, 0.5f, 0.0f}, {0, 0, 1}).irradiance.x;
  CHECK(rel(centre, 3.0 * 4.0 * parallel_corner_rect(1.0, 0.5, 1.5)) < 1e-3);
  // Tilted rects (fully above the horizon, in front): n . Phi of the reference's Lambert formula.
  const glm::vec3 normals[] = {glm::normalize(glm::vec3(0.3f, -0.2f, -1.0f)), glm::normalize(glm::vec3(-1.0f, 0.1f, -0.4f))};
  for (const glm::vec3& nl : normals) {
    const light t = rect_light({0.4f, -0.3f, 2.0f}, nl, {0, 1, 0.1f}, 0.8f, 0.5f, 2.0f);
    const light_set ts(&t, 1);
    const light_set::prepared& pr = ts.prepared_light(0);
    const glm::dvec3 c(pr.l.position), u = glm::dvec3(pr.l.tangent) * 0.4, v = glm::dvec3(pr.bitangent) * 0.25;
    for (const glm::vec3 p : {glm::vec3(0, 0, 0), glm::vec3(1.5f, 0.2f, 0.0f), glm::vec3(-1.0f, -1.0f, 0.0f)}) {
      if (glm::dot(glm::dvec3(p) - c, glm::dvec3(pr.l.direction)) <= 0.0) continue;
      const std::vector<glm::dvec3> poly = {c - u - v, c + u - v, c + u + v, c - u + v};
      const double expected = polygon_vector_irradiance(poly, glm::dvec3(p), 2.0).z;
      const light_sample ls = direct_light(*s, ts, 0, p, {0, 0, 1});
      CHECK(rel(ls.irradiance.x, expected) < 1e-3);
      CHECK(ls.visibility == 1.0f);
      const glm::dvec3 phi = polygon_vector_irradiance(poly, glm::dvec3(p), 1.0);
      CHECK(glm::length(glm::dvec3(ls.direction) - glm::normalize(phi)) < 1e-5);
    }
  }
}

TEST_CASE("lights: a RECT is one-sided, and across the horizon matches area quadrature", "[lights]") {
  const auto s = make(scene_mesh{});
  // Facing up at height 1: a point below it is behind the emitting side.
  const light up = rect_light({0, 0, 1}, {0, 0, 1}, {1, 0, 0}, 1.0f, 1.0f, 1.0f);
  const light_set us(&up, 1);
  CHECK(direct_light(*s, us, 0, {0, 0, 0}, {0, 0, 1}).irradiance == glm::vec3(0.0f));
  CHECK(direct_light(*s, us, 0, {0.2f, 0, 0}, {0, 0, 1}).unoccluded == glm::vec3(0.0f));
  CHECK(direct_light(*s, us, 0, {3.0f, 0, 1.0f}, {0, 0, 1}).irradiance == glm::vec3(0.0f));  // in its plane
  // A vertical rect (normal -x) standing across the receiver's plane z = 0 (z from -0.4 to 0.6):
  // the part below the horizon must not count.
  for (const glm::vec3 p : {glm::vec3(-1.0f, 0.0f, 0.0f), glm::vec3(-0.3f, 0.4f, 0.0f), glm::vec3(-2.0f, -1.0f, 0.0f)}) {
    const light v = rect_light({0.0f, 0.0f, 0.1f}, {-1, 0, 0}, {0, 1, 0}, 1.2f, 1.0f, 2.0f);
    const light_set vs(&v, 1);
    const light_set::prepared& pr = vs.prepared_light(0);
    const double expected = 2.0 * rect_quadrature(glm::dvec3(p), glm::dvec3(pr.l.position),
                                                  glm::dvec3(pr.l.tangent) * 1.2, glm::dvec3(pr.bitangent) * 1.0,
                                                  glm::dvec3(pr.l.direction), 2000);
    const light_sample ls = direct_light(*s, vs, 0, p, {0, 0, 1});
    INFO("p " << p.x << " " << p.y << ": " << ls.irradiance.x << " vs " << expected);
    // 1e-3: the closed form is exact; midpoint quadrature on 2000^2 cells is good to ~1e-5 here.
    CHECK(rel(ls.irradiance.x, expected) < 1e-3);
    CHECK(ls.visibility == 1.0f);  // no occluder: every sample above the horizon is visible
  }
}

TEST_CASE("lights: a hard shadow of a square occluder (umbra exactly 0, outside exactly the closed form)", "[lights]") {
  scene_mesh m = floor_mesh();
  m.add_quad({-0.5f, -0.5f, 1.0f}, {0.5f, -0.5f, 1.0f}, {0.5f, 0.5f, 1.0f}, {-0.5f, 0.5f, 1.0f}, material{});
  const auto s = make(m);
  const light l = point_light({0.0f, 0.0f, 3.0f}, 7.0f);
  const light_set set(&l, 1);
  // The shadow on the floor is the square scaled by 3 / (3 - 1) = 1.5: |x|, |y| < 0.75.
  int umbra = 0, lit = 0;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) {
      const glm::vec3 p(0.05f * float(i), 0.05f * float(j), 0.0f);
      const float mx = std::max(std::fabs(p.x), std::fabs(p.y));
      if (std::fabs(mx - 0.75f) < 0.01f) continue;  // the edge itself
      const light_sample ls = direct_light(*s, set, 0, p, {0, 0, 1});
      if (mx < 0.75f) {
        ++umbra;
        CHECK(ls.irradiance == glm::vec3(0.0f));
        CHECK(ls.visibility == 0.0f);
      } else {
        ++lit;
        CHECK(ls.irradiance == ls.unoccluded);
        const glm::dvec3 d = glm::dvec3(l.position) - glm::dvec3(p);
        CHECK(rel(ls.irradiance.x, 7.0 * (d.z / glm::length(d)) / glm::dot(d, d)) < 1e-3);
      }
    }
  CHECK(umbra > 400);
  CHECK(lit > 400);
}

TEST_CASE("lights: a RECT's penumbra under a half-plane occluder matches Lambert's formula on its visible part",
          "[lights]") {
  // Light: 1 x 1 m at z = 2 facing down, radiance 1. Occluder: the half-plane x < 0 at z = 1. From
  // a floor point (x0, y0, 0) the segment to a light point (xq, yq, 2) crosses z = 1 at
  // x = (x0 + xq) / 2, so the visible part is the light's strip xq > -x0 (a rectangle).
  scene_mesh m = floor_mesh();
  m.add_quad({-10.0f, -10.0f, 1.0f}, {0.0f, -10.0f, 1.0f}, {0.0f, 10.0f, 1.0f}, {-10.0f, 10.0f, 1.0f}, material{});
  const auto s = make(m);
  const light l = rect_light({0, 0, 2}, {0, 0, -1}, {1, 0, 0}, 1.0f, 1.0f, 1.0f);
  const light_set set(&l, 1);
  direct_options reference;
  reference.probe_samples = 4096;
  reference.penumbra_samples = 4096;
  double sq = 0.0, sq_ref = 0.0, worst = 0.0;
  int count = 0;
  for (int k = 0; k <= 120; ++k) {
    const double x0 = -0.6 + 1.2 * k / 120.0, y0 = 0.013 * k - 0.7;
    const double lo = std::max(-0.5, -x0);
    std::vector<glm::dvec3> visible;
    double exact = 0.0;
    if (lo < 0.5) {
      visible = {{lo, -0.5, 2.0}, {0.5, -0.5, 2.0}, {0.5, 0.5, 2.0}, {lo, 0.5, 2.0}};
      exact = polygon_vector_irradiance(visible, {x0, y0, 0.0}, 1.0).z;
    }
    const glm::vec3 p(float(x0), float(y0), 0.0f);
    const light_sample ls = direct_light(*s, set, 0, p, {0, 0, 1});
    const double full = ls.unoccluded.x;
    const double err = (ls.irradiance.x - exact) / full;
    const double err_ref = (direct_light(*s, set, 0, p, {0, 0, 1}, reference).irradiance.x - exact) / full;
    INFO("x0 " << x0 << ": " << ls.irradiance.x << " exact " << exact << " full " << full);
    // 2% of the unoccluded irradiance at every point (docs/lights.md): 64 samples of a (0, 6, 2)
    // net cut by a straight edge err by at most ~8 strata x 1/64 x (their weight spread) / 2.
    CHECK(std::fabs(err) < 0.02);
    worst = std::max(worst, std::fabs(err));
    sq += err * err;
    sq_ref += err_ref * err_ref;
    ++count;
  }
  const double rms = std::sqrt(sq / count), rms_ref = std::sqrt(sq_ref / count);
  INFO("RMS error " << rms << " (worst " << worst << "), 4096 samples " << rms_ref);
  CHECK(rms < 0.01);      // 1% RMS of the unoccluded irradiance over the penumbra with the defaults
  CHECK(rms_ref < 0.002);  // 4096 samples
  WARN("half-plane penumbra of a RECT: RMS " << rms << " worst " << worst << " of unoccluded E (4096 samples: "
                                             << rms_ref << ")");
}

TEST_CASE("lights: casts_shadows = false ignores occluders", "[lights]") {
  scene_mesh m = floor_mesh();
  m.add_box({-1, -1, 0.5f}, {1, 1, 1}, material{});  // a slab over the point
  const auto s = make(m);
  light lights[3] = {point_light({0, 0, 3}, 2.0f), point_light({0.2f, 0, 3}, 2.0f, 0.3f),
                     rect_light({0, 0, 2.5f}, {0, 0, -1}, {1, 0, 0}, 0.5f, 0.5f, 1.0f)};
  for (light& l : lights) {
    light_set shadowed(&l, 1);
    CHECK(direct_light(*s, shadowed, 0, {0, 0, 0}, {0, 0, 1}).irradiance == glm::vec3(0.0f));
    l.casts_shadows = false;
    const light_set unshadowed(&l, 1);
    const light_sample ls = direct_light(*s, unshadowed, 0, {0, 0, 0}, {0, 0, 1});
    CHECK(ls.irradiance == ls.unoccluded);
    CHECK(ls.irradiance.x > 0.0f);
    CHECK(ls.visibility == 1.0f);
  }
}

TEST_CASE("lights: bad lights give invalid_argument naming the index and the field", "[lights]") {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  struct bad_case {
    void (*edit)(light&);
    const char* needle;
  };
  const bad_case cases[] = {
      {[](light& l) { l.type = static_cast<light_type>(7); }, "lights[2].type = 7 is unknown"},
      {[](light& l) { l.color[1] = -1.0f; }, "lights[2].color.g = -1 is negative"},
      {[](light& l) { l.position.y = std::numeric_limits<float>::quiet_NaN(); }, "lights[2].position.y is nan"},
      {[](light& l) { l.width = std::numeric_limits<float>::infinity(); }, "lights[2].width is inf"},
      {[](light& l) { l.spot_outer = std::numeric_limits<float>::quiet_NaN(); }, "lights[2].spot_outer is nan"},
      {[](light& l) { l.type = light_type::spot; l.spot_outer = 1.7f; }, "lights[2].spot_outer = 1.70000005 is past pi/2"},
      {[](light& l) { l.type = light_type::spot; l.spot_inner = 0.5f; l.spot_outer = 0.4f; }, "lights[2].spot_inner"},
      {[](light& l) { l.type = light_type::spot; l.spot_inner = -0.1f; }, "lights[2].spot_inner"},
      {[](light& l) { l.type = light_type::spot; l.direction = glm::vec3(0.0f); }, "lights[2].direction is zero"},
      {[](light& l) { l.type = light_type::directional; l.direction = glm::vec3(0.0f); }, "lights[2].direction is zero"},
      {[](light& l) { l.type = light_type::directional; l.radius = 2.0f; }, "lights[2].radius = 2 is past pi/2"},
      {[](light& l) { l.radius = -0.1f; }, "lights[2].radius"},
      {[](light& l) { l.type = light_type::rect; l.width = 0.0f; }, "lights[2].width = 0 is not positive"},
      {[](light& l) { l.type = light_type::rect; l.height = -1.0f; }, "lights[2].height"},
      {[](light& l) { l.type = light_type::rect; l.tangent = glm::vec3(0.0f); }, "lights[2].tangent is zero"},
      {[](light& l) { l.type = light_type::rect; l.direction = glm::vec3(0.0f); }, "lights[2].direction is zero"},
      {[](light& l) { l.type = light_type::rect; l.tangent = {0, -2, 0}; }, "lights[2].tangent is parallel"},
  };
  (void)nan;
  (void)inf;
  for (const bad_case& c : cases) {
    INFO(c.needle);
    light ls[3];
    c.edit(ls[2]);
    require_error([&] { validate_lights(ls, 3); }, status::invalid_argument, c.needle);
    require_error([&] { light_set set(ls, 3); }, status::invalid_argument, c.needle);
  }
  require_error([] { validate_lights(nullptr, 2); }, status::invalid_argument, "lights is null");
  validate_lights(nullptr, 0);
  // Unused fields may be anything finite; tiny and huge direction vectors are fine.
  light ok[3];
  ok[0].type = light_type::point;
  ok[0].direction = glm::vec3(0.0f);  // a point light has no direction
  ok[1].type = light_type::spot;
  ok[1].direction = {0.0f, -1e-40f, 1e-41f};  // subnormal
  ok[2].type = light_type::rect;
  ok[2].direction = {0.0f, 0.0f, -3e38f};
  ok[2].tangent = {3e38f, 0.0f, 3e38f};  // huge, not orthogonal: made orthogonal
  const light_set set(ok, 3);
  CHECK(glm::length(set[1].direction) == Approx(1.0f).epsilon(1e-6));
  CHECK(set[1].direction.y < -0.99f);
  CHECK(set[2].tangent.x == Approx(1.0f).epsilon(1e-6));
  CHECK(set[2].tangent.z == Approx(0.0f).margin(1e-6));
  direct_options bad;
  bad.probe_samples = -1;
  const auto s = make(floor_mesh());
  require_error([&] { direct_light(*s, set, 0, {0, 0, 0}, {0, 0, 1}, bad); }, status::invalid_argument, "probe_samples");
  bad = direct_options{};
  bad.penumbra_samples = 2;  // below probe_samples = 4
  require_error([&] { direct_irradiance(*s, set, {0, 0, 0}, {0, 0, 1}, bad); }, status::invalid_argument,
                "penumbra_samples");
  bad = direct_options{};
  bad.offset_scale = -1.0f;
  require_error([&] { direct_irradiance(*s, set, {0, 0, 0}, {0, 0, 1}, bad); }, status::invalid_argument, "offset_scale");
}

TEST_CASE("lights: per-point results are bitwise the same in any call order and on any thread", "[lights]") {
  scene_mesh m = floor_mesh();
  m.add_box({-0.3f, -0.3f, 0.0f}, {0.3f, 0.3f, 0.8f}, material{});
  const auto s = make(m);
  light sun;
  sun.type = light_type::directional;
  sun.direction = glm::normalize(glm::vec3(0.4f, 0.3f, -1.0f));
  sun.radius = 0.05f;
  sun.color = glm::vec3(5.0f);
  const light lights[3] = {sun, point_light({1, 0.5f, 2}, 3.0f, 0.2f),
                           rect_light({0, 0, 2}, {0, 0, -1}, {1, 0, 0}, 1.0f, 0.6f, 1.0f)};
  const light_set set(lights, 3);
  std::vector<glm::vec3> points;
  for (int i = 0; i < 400; ++i) points.push_back({-1.0f + 0.005f * float(i), 0.4f - 0.002f * float(i), 0.0f});
  std::vector<glm::vec3> forward(points.size()), backward(points.size()), threaded(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) forward[i] = direct_irradiance(*s, set, points[i], {0, 0, 1});
  for (std::size_t i = points.size(); i-- > 0;) backward[i] = direct_irradiance(*s, set, points[i], {0, 0, 1});
  parallel_for(points.size(), 2, 7, [&](int, std::size_t b, std::size_t e) {
    for (std::size_t i = e; i-- > b;) threaded[i] = direct_irradiance(*s, set, points[i], {0, 0, 1});
  });
  int penumbra = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    CHECK(std::memcmp(&forward[i], &backward[i], sizeof(glm::vec3)) == 0);
    CHECK(std::memcmp(&forward[i], &threaded[i], sizeof(glm::vec3)) == 0);
    light_sample per[3];
    const glm::vec3 total = direct_irradiance(*s, set, points[i], {0, 0, 1}, {}, per);
    CHECK(std::memcmp(&total, &forward[i], sizeof(glm::vec3)) == 0);
    CHECK(total == per[0].irradiance + per[1].irradiance + per[2].irradiance);
    for (const light_sample& ls : per) {
      if (ls.visibility > 0.0f && ls.visibility < 1.0f) ++penumbra;
      if (ls.irradiance.x > 0.0f) CHECK(glm::length(ls.direction) == Approx(1.0f).epsilon(1e-5));
    }
  }
  CHECK(penumbra > 20);  // the points do cross penumbrae, where the sampling pattern matters
}

TEST_CASE("lights: emissive_rects_to_lights turns the Cornell box's light quad into its RECT light", "[lights]") {
  scene_mesh m = cornell_box();
  const scene_mesh original = m;
  const std::vector<light> ls = emissive_rects_to_lights(m);
  REQUIRE(ls.size() == 1);
  const light& l = ls[0];
  // The quad (reference_scenes.cpp): 0.13 x 0.105 m centred at (0.278, 0.5478, 0.2795), facing
  // down, radiance (17, 12, 4); the same light cornell_box_rect_light places by hand.
  const light by_hand = cornell_box_rect_light().lights.at(0);
  CHECK(l.type == light_type::rect);
  CHECK(glm::length(l.position - by_hand.position) < 1e-6f);
  CHECK(glm::length(glm::normalize(l.direction) - glm::vec3(0, -1, 0)) < 1e-6f);
  CHECK(l.color == by_hand.color);
  CHECK(l.casts_shadows);
  const bool along_x = std::fabs(l.tangent.x) > 0.999f;
  CHECK((along_x || std::fabs(l.tangent.z) > 0.999f));
  CHECK(std::fabs((along_x ? l.width : l.height) - 0.13f) < 1e-6f);
  CHECK(std::fabs((along_x ? l.height : l.width) - 0.105f) < 1e-6f);
  // The quad stays as geometry and stops emitting; nothing else changes.
  REQUIRE(m.positions == original.positions);
  REQUIRE(m.indices == original.indices);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    CHECK(m.materials[t].emission == glm::vec3(0.0f));
    CHECK(m.materials[t].albedo == original.materials[t].albedo);
  }
  // The light gives what the triangles gave: Lambert's formula over the original two triangles
  // (tests/raycast_reference.hpp, independent of the conversion) at floor and wall points.
  const light_set set(ls.data(), ls.size());
  for (const auto& pn : {std::pair<glm::vec3, glm::vec3>{{0.2f, 0.0f, 0.3f}, {0, 1, 0}}, {{0.556f, 0.3f, 0.2f}, {-1, 0, 0}},
                         {{0.1f, 0.25f, 0.5592f}, {0, 0, -1}}}) {
    glm::dvec3 phi(0.0);
    for (std::size_t t = 0; t < original.triangle_count(); ++t) {
      const glm::vec3 e = original.materials[t].emission;
      if (e == glm::vec3(0.0f)) continue;
      std::vector<glm::dvec3> tri;
      for (int k = 0; k < 3; ++k) tri.push_back(glm::dvec3(original.positions[original.indices[3 * t + std::size_t(k)]]));
      phi += polygon_vector_irradiance(tri, glm::dvec3(pn.first), double(e.x));
    }
    const double expected = glm::dot(phi, glm::dvec3(pn.second));
    CHECK(rel(unoccluded_irradiance(set, 0, pn.first, pn.second).x, expected) < 1e-4);  // both exact: float rounding
  }
}

TEST_CASE("lights: emissive_rects_to_lights leaves other emitters alone", "[lights]") {
  const material glow{{2.0f, 2.0f, 2.0f}, glm::vec3(0.5f), false};
  const auto untouched = [](scene_mesh m, const char* what) {
    const scene_mesh before = m;
    INFO(what);
    CHECK(emissive_rects_to_lights(m).empty());
    for (std::size_t t = 0; t < m.triangle_count(); ++t) CHECK(m.materials[t].emission == before.materials[t].emission);
  };
  scene_mesh lone;
  lone.add_triangle({0, 0, 1}, {1, 0, 1}, {0, 1, 1}, glow);
  untouched(lone, "a lone triangle");
  scene_mesh slanted;  // a parallelogram, not a rectangle
  slanted.add_quad({0, 0, 1}, {1, 0, 1}, {1.5f, 1, 1}, {0.5f, 1, 1}, glow);
  untouched(slanted, "a parallelogram");
  scene_mesh both_sides;
  both_sides.add_quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, material{{2.0f, 2.0f, 2.0f}, glm::vec3(0.5f), true});
  untouched(both_sides, "a two-sided rectangle");
  scene_mesh two_colours;
  two_colours.add_triangle({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, glow);
  two_colours.add_triangle({0, 0, 1}, {1, 1, 1}, {0, 1, 1}, material{{2.0f, 2.0f, 2.5f}, glm::vec3(0.5f), false});
  untouched(two_colours, "two emissions");
  scene_mesh folded;  // the second triangle faces the other way
  folded.add_triangle({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, glow);
  folded.add_triangle({0, 0, 1}, {0, 1, 1}, {1, 1, 1}, glow);
  untouched(folded, "opposite facings");
  scene_mesh bent;  // a rectangle folded along its diagonal by 1% of it
  bent.add_triangle({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, glow);
  bent.add_triangle({0, 0, 1}, {1, 1, 1}, {0, 1, 1.014f}, glow);
  untouched(bent, "a folded rectangle");
  // Separate vertices (add_triangle) still pair: edges match by position.
  scene_mesh split;
  split.add_triangle({0, 0, 1}, {2, 0, 1}, {2, 1, 1}, glow);
  split.add_triangle({0, 0, 1}, {2, 1, 1}, {0, 1, 1}, glow);
  const std::vector<light> ls = emissive_rects_to_lights(split);
  REQUIRE(ls.size() == 1);
  CHECK(ls[0].width * ls[0].height == Approx(2.0f).epsilon(1e-6));
  CHECK(glm::length(ls[0].position - glm::vec3(1.0f, 0.5f, 1.0f)) < 1e-6f);
  CHECK(glm::length(ls[0].direction - glm::vec3(0, 0, 1)) < 1e-6f);
}
