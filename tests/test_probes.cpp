// Tests of probes.hpp against references that do not come from the library: the closed-form
// solid angle of a texel (geometry's rectangle formula, itself tested against Lambert), the SH
// integral of a uniform sky (2 sqrt(pi) L), direct quadrature of L Y_k over an emitter's area
// written out here, the point light's I / d^2 Y_k(w), and the clamped-cosine convolution of a
// delta source (the Funk-Hecke constants).
#include "hemilight/probes.hpp"

#include "hemilight/geometry.hpp"
#include "hemilight/reference_scenes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

using namespace hemilight;

namespace {

constexpr double pi = 3.14159265358979323846;

// The basis written out independently of the library (the coefficients of probes.hpp's table).
void basis(const glm::dvec3& w, double (&y)[9]) {
  y[0] = 0.5 * std::sqrt(1.0 / pi);
  y[1] = std::sqrt(3.0 / (4.0 * pi)) * w.y;
  y[2] = std::sqrt(3.0 / (4.0 * pi)) * w.z;
  y[3] = std::sqrt(3.0 / (4.0 * pi)) * w.x;
  y[4] = 0.5 * std::sqrt(15.0 / pi) * w.x * w.y;
  y[5] = 0.5 * std::sqrt(15.0 / pi) * w.y * w.z;
  y[6] = 0.25 * std::sqrt(5.0 / pi) * (3.0 * w.z * w.z - 1.0);
  y[7] = 0.5 * std::sqrt(15.0 / pi) * w.x * w.z;
  y[8] = 0.25 * std::sqrt(15.0 / pi) * (w.x * w.x - w.y * w.y);
}

std::shared_ptr<const scene> empty_scene(glm::vec3 sky) {
  scene_mesh m;
  m.sky_radiance = sky;
  return scene::create(m.desc());
}

}  // namespace

TEST_CASE("probes: the basis is the real SH of the stated constants", "[probes]") {
  const glm::dvec3 w = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
  double ref[9];
  basis(w, ref);
  const std::array<float, 9> y = sh9_basis(glm::vec3(w));
  for (int k = 0; k < 9; ++k) CHECK(y[std::size_t(k)] == Approx(ref[k]).epsilon(1e-6).margin(1e-7));
}

TEST_CASE("probes: a uniform sky gives c0 = 2 sqrt(pi) L and nothing else", "[probes]") {
  const glm::vec3 L(1.0f, 2.0f, 0.5f);
  for (const int n : {2, 16, 64}) {
    probe_options o;
    o.resolution = n;
    const glm::vec3 p(0.2f, -0.1f, 0.3f);
    const probe_result r = sample_probes(empty_scene(L), &p, 1, o);
    // Float tables summed in double over 6 N^2 texels: 1e-5 relative.
    for (int c = 0; c < 3; ++c) CHECK(r.probes[0][0][c] == Approx(2.0 * std::sqrt(pi) * L[c]).epsilon(1e-5));
    for (int k = 1; k < 9; ++k)
      for (int c = 0; c < 3; ++c) CHECK(std::fabs(r.probes[0][std::size_t(k)][c]) < 1e-5f * L[c]);
    CHECK(r.backface_fraction[0] == 0.0f);
    // Its irradiance for any normal is pi L (band 0 only): exact up to float rounding.
    const glm::vec3 e = sh9_irradiance(r.probes[0], {0.3f, 0.4f, -2.0f});
    for (int c = 0; c < 3; ++c) CHECK(e[c] == Approx(pi * L[c]).epsilon(1e-5));
  }
}

namespace {

// c_k of a parallelogram of radiance 1 (corner a, sides u and v, relative to the probe): the sum
// over a 400 x 400 grid of the quad of Y_k(w) |cos(theta')| dA / r^2 (midpoint rule, double:
// converged to ~1e-6).
std::array<double, 9> quad_sh9(const glm::dvec3& a, const glm::dvec3& u, const glm::dvec3& v) {
  std::array<double, 9> ref{};
  const int g = 400;
  const glm::dvec3 normal = glm::normalize(glm::cross(u, v));
  const double area = glm::length(glm::cross(u, v));
  for (int i = 0; i < g; ++i)
    for (int j = 0; j < g; ++j) {
      const glm::dvec3 q = a + (i + 0.5) / g * u + (j + 0.5) / g * v;
      const double r2 = glm::dot(q, q);
      const glm::dvec3 w = q / std::sqrt(r2);
      const double domega = std::fabs(glm::dot(normal, w)) * area / (double(g) * g) / r2;
      double y[9];
      basis(w, y);
      for (int k = 0; k < 9; ++k) ref[std::size_t(k)] += y[k] * domega;
    }
  return ref;
}

}  // namespace

TEST_CASE("probes: an emissive quad against quadrature of L Y_k over its area", "[probes]") {
  // A 0.8 x 0.6 emitter (radiance 1, 0.5, 0.25) tilted, above and to the side of the probe,
  // facing it; no sky. Reference: quad_sh9.
  const glm::dvec3 a(-0.3, -0.2, 1.0), b(0.5, -0.2, 1.2), d(-0.3, 0.4, 0.9);  // corners a, b = a + u, d = a + v
  const glm::dvec3 u = b - a, v = d - a, c4 = a + u + v;
  scene_mesh m;
  material em;
  em.emission = {1.0f, 0.5f, 0.25f};
  // Front face towards the probe at the origin (counter-clockwise seen from it).
  m.add_quad(glm::vec3(a), glm::vec3(d), glm::vec3(c4), glm::vec3(b), em);
  const auto s = scene::create(m.desc());
  const glm::dvec3 normal = glm::normalize(glm::cross(v, u));  // towards the origin
  REQUIRE(glm::dot(normal, -a) > 0.0);
  const std::array<double, 9> ref = quad_sh9(a, u, v);
  probe_options o;
  o.resolution = 128;
  const glm::vec3 origin(0.0f);
  const probe_result r = sample_probes(s, &origin, 1, o);
  // The bound docs/probes.md states: 1% of c0 at N = 128 (the emitter's outline cuts texels).
  for (std::size_t k = 0; k < 9; ++k) {
    INFO("k = " << k << ": " << r.probes[0][k].x << " against " << ref[k]);
    CHECK(std::fabs(r.probes[0][k].x - ref[k]) < 0.01 * ref[0]);
    CHECK(std::fabs(r.probes[0][k].y - 0.5 * ref[k]) < 0.01 * 0.5 * ref[0]);
  }
}

TEST_CASE("probes: exact edge coverage removes the edge aliasing of an emitter's coefficients", "[probes]") {
  // The rectangle [-0.5, 0.5] x [0.3, 0.9] at z = 1 of docs/raster.md's edge-coverage figures,
  // radiance 1, facing down, probed from (0.05, -0.02, 0) at N = 16 to 128, with and without
  // probe_options::edge_coverage. Reference: quad_sh9.
  const glm::dvec3 eye(0.05, -0.02, 0.0);
  const glm::dvec3 a(-0.5, 0.3, 1.0), u(1.0, 0.0, 0.0), v(0.0, 0.6, 0.0);
  scene_mesh m;
  material em;
  em.emission = glm::vec3(1.0f);
  m.add_quad(glm::vec3(a), glm::vec3(a + v), glm::vec3(a + u + v), glm::vec3(a + u), em);  // normal -z
  const auto s = scene::create(m.desc());
  const std::array<double, 9> ref = quad_sh9(a - eye, u, v);
  // Tolerances on the worst |c_k - ref_k| / c_0 over the 9 coefficients (docs/probes.md's table
  // is this test's output with -s). Point sampling gains or loses whole rows of texels along the
  // edges: measured 25.5%, 5.0%, 2.6% and 3.2% at N = 16, 32, 64 and 128 (asserted > 10% at 16,
  // > 1% above: what the option fixes). Exact coverage leaves the covered fraction measured in
  // projected solid angle (the rasterizer's weight) while the probe weights each texel by the
  // basis, whose variation within a partial texel is first order in its size for that texel
  // (second order in all): measured 1.24% (Y_5, y z), 0.11%, 0.054% and 0.021%, asserted at about
  // twice that. c_2 (Y_2 ~ cos) is weighted as the rasterizer weighs: measured 1e-5, asserted 1e-4.
  const struct {
    int n;
    double point_above, exact_below;
  } cases[] = {{16, 0.10, 0.02}, {32, 0.01, 0.002}, {64, 0.01, 0.001}, {128, 0.01, 0.0005}};
  for (const auto& c : cases) {
    probe_options o;
    o.resolution = c.n;
    const glm::vec3 p(eye);
    const probe_result point = sample_probes(s, &p, 1, o);
    o.raster.edge_coverage = true;
    const probe_result exact = sample_probes(s, &p, 1, o);
    double worst_point = 0.0, worst_exact = 0.0;
    for (std::size_t k = 0; k < 9; ++k) {
      INFO("N = " << c.n << ", k = " << k << ": " << point.probes[0][k].x << " and " << exact.probes[0][k].x << " against "
                  << ref[k]);
      worst_point = std::max(worst_point, std::fabs(point.probes[0][k].x - ref[k]) / ref[0]);
      worst_exact = std::max(worst_exact, std::fabs(exact.probes[0][k].x - ref[k]) / ref[0]);
      CHECK(exact.probes[0][k].x == exact.probes[0][k].y);
    }
    INFO("N = " << c.n << ": worst |c_k - ref_k| / c_0: point sampling " << worst_point << ", exact edge coverage " << worst_exact);
    CHECK(worst_point > c.point_above);
    CHECK(worst_exact < c.exact_below);
    CHECK(std::fabs(exact.probes[0][2].x - ref[2]) < 1e-4 * ref[0]);
  }
}

TEST_CASE("probes: a point light adds I / d^2 Y_k towards it, and nothing in its shadow", "[probes]") {
  light l;
  l.type = light_type::point;
  l.position = {1.0f, 2.0f, 2.0f};  // d = 3 from the origin
  l.color = {9.0f, 4.5f, 0.0f};
  auto lights = std::make_shared<const light_set>(&l, 1);
  probe_options o;
  o.resolution = 8;
  o.lights = lights;
  const glm::vec3 origin(0.0f);
  const probe_result r = sample_probes(empty_scene(glm::vec3(0.0f)), &origin, 1, o);
  double y[9];
  basis(glm::dvec3(1.0, 2.0, 2.0) / 3.0, y);
  for (int k = 0; k < 9; ++k) CHECK(r.probes[0][std::size_t(k)].x == Approx(9.0 / 9.0 * y[k]).epsilon(1e-5).margin(1e-6));
  // Facing the light, the band-limited irradiance of a delta source is
  // (I / d^2) (pi Y0^2 + 2 pi / 3 sum Y1^2 + pi / 4 sum Y2^2) = 1.0625 I / d^2 (Funk-Hecke).
  const glm::vec3 e = sh9_irradiance(r.probes[0], {1.0f, 2.0f, 2.0f});
  CHECK(e.x == Approx(1.0625).epsilon(1e-5));
  // A black square between the probe and the light: every coefficient 0.
  scene_mesh m;
  m.add_quad({0.0f, 0.5f, 1.5f}, {1.0f, 0.5f, 1.5f}, {1.0f, 1.5f, 0.5f}, {0.0f, 1.5f, 0.5f}, material{});
  const probe_result shadowed = sample_probes(scene::create(m.desc()), &origin, 1, o);
  for (int k = 0; k < 9; ++k) CHECK(shadowed.probes[0][std::size_t(k)] == glm::vec3(0.0f));
}

TEST_CASE("probes: inside closed geometry the back-face fraction is 1; inside a room it is about 0", "[probes]") {
  scene_mesh box;  // a closed box, faces outwards
  const material grey{{0.2f, 0.2f, 0.2f}, {}, false};
  const glm::vec3 lo(-1.0f), hi(1.0f);
  box.add_quad({lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, lo.y, lo.z}, grey);  // -z
  box.add_quad({lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, grey);  // +z
  box.add_quad({lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}, grey);  // -y
  box.add_quad({lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, grey);  // +y
  box.add_quad({lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}, grey);  // -x
  box.add_quad({hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}, grey);  // +x
  const glm::vec3 inside(0.1f, 0.2f, -0.3f);
  const probe_result in_box = sample_probes(scene::create(box.desc()), &inside, 1, probe_options{});
  CHECK(in_box.backface_fraction[0] == Approx(1.0).epsilon(1e-5));
  const glm::vec3 in_room(0.25f, 0.25f, 0.25f);
  const probe_result room = sample_probes(scene::create(cornell_box().desc()), &in_room, 1, probe_options{});
  // The Cornell box's walls meet edge to edge: a few texels along their seams may catch a back
  // face (4e-5 measured); nothing like the inside of a box.
  CHECK(room.backface_fraction[0] < 1e-3f);
  CHECK(room.probes[0][0].x > 0.0f);
}

TEST_CASE("probes: bitwise the same on 1, 2 and 3 threads; bad input is named", "[probes]") {
  const auto s = scene::create(hexagon_room(2).desc());
  std::vector<glm::vec3> p;
  for (int i = 0; i < 23; ++i) p.push_back({-1.5f + 0.13f * float(i), 1.0f + 0.05f * float(i % 5), 0.4f - 0.07f * float(i)});
  probe_options o;
  o.resolution = 16;
  o.thread_count = 1;
  const probe_result one = sample_probes(s, p.data(), p.size(), o);
  for (const int t : {2, 3}) {
    o.thread_count = t;
    const probe_result many = sample_probes(s, p.data(), p.size(), o);
    CHECK(std::memcmp(many.probes.data(), one.probes.data(), p.size() * sizeof(sh9_rgb)) == 0);
    CHECK(many.backface_fraction == one.backface_fraction);
  }
  p[17].y = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH(sample_probes(s, p.data(), p.size(), o), Catch::Contains("positions[17].y is nan"));
  p[17].y = 1.0f;
  o.resolution = 7;
  CHECK_THROWS_WITH(sample_probes(s, p.data(), p.size(), o), Catch::Contains("resolution 7"));
  o.resolution = 16;
  o.thread_count = -2;
  CHECK_THROWS_WITH(sample_probes(s, p.data(), p.size(), o), Catch::Contains("thread_count is -2"));
  CHECK_THROWS_WITH(sample_probes(nullptr, p.data(), p.size(), probe_options{}), Catch::Contains("scene is null"));
  CHECK_THROWS_WITH(sample_probes(s, nullptr, 3, probe_options{}), Catch::Contains("positions is null"));
  CHECK(sample_probes(s, nullptr, 0, probe_options{}).probes.empty());
  CHECK(sh9_irradiance(one.probes[0], glm::vec3(0.0f)) == glm::vec3(0.0f));
}
