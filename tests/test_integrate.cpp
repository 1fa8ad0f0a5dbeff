// Tests of integrate.hpp against references that do not come from the integrator: closed forms
// (pi L, Lambert's polygon formula and its vector irradiance, 3h/2, the tilted-plane sky view
// factor), central differences of those closed forms, and central differences of hemicubes
// re-rendered by the reference ray caster (tests/raycast_reference.hpp).
#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"

#include "integrate_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace hemilight;
using namespace hemilight::test;

namespace {

constexpr double pi = 3.14159265358979323846;

constexpr double default_roll = 0.3;  // radians; see rolled_frame

hemicube_buffer render(const closed_form_scene& s, int n, const glm::dvec3& x, const glm::dvec3& normal,
                       double roll = default_roll) {
  return raycast_hemicube(s.tris, s.sky, x, rolled_frame(normal, roll), n);
}

// Sum, over the texels whose four corner rays and centre ray do not all see the same triangle
// (or all miss), of a per-texel weight: the texels where sampling the centre can be wrong. The
// error of any texel-centre quadrature of a piecewise-constant radiance is at most
// (max radiance difference) x this sum: a rigorous discretisation bound, computed independently.
struct boundary_stats {
  double sum = 0.0;     // rigorous bound: sum of the weights of the cut texels
  double sum_sq = 0.0;  // for the statistical bound
  /// Each cut texel is off by (covered - fraction) x weight; with the outline's position in the
  /// texel uniformly distributed that is a zero-mean error of variance weight^2 / 12, so the
  /// total error has standard deviation sqrt(sum_sq / 12). Four of them: a 1-in-15,000 bound.
  double statistical() const { return 4.0 * std::sqrt(sum_sq / 12.0); }
};

boundary_stats boundary_weights(const closed_form_scene& s, int n, const glm::dvec3& x, const glm::dvec3& normal,
                                bool projected, double roll = default_roll) {
  const frame f = rolled_frame(normal, roll);
  const glm::dvec3 t(f.t), b(f.b), nn(f.n);
  boundary_stats out;
  for (std::size_t i = 0; i < hemicube_texel_count(n); ++i) {
    const auto corners = hemicube_texel_corners(n, i);
    const glm::dvec3 centre(hemicube_texel_direction(n, i));
    int first = -2;
    bool mixed = false;
    for (const glm::dvec3& local : {corners[0], corners[1], corners[2], corners[3], centre}) {
      int hit;
      bool back;
      cast(s.tris, x, glm::normalize(t * local.x + b * local.y + nn * local.z), hit, back);
      if (first == -2) first = hit;
      else if (hit != first) mixed = true;
    }
    if (mixed) {
      const double w = projected ? hemicube_texel_projected_solid_angle(n, i) : hemicube_texel_solid_angle(n, i);
      out.sum += w;
      out.sum_sq += w * w;
    }
  }
  return out;
}

double boundary_weight(const closed_form_scene& s, int n, const glm::dvec3& x, const glm::dvec3& normal, bool projected,
                       double roll = default_roll) {
  return boundary_weights(s, n, x, normal, projected, roll).sum;
}

double rel(const glm::dvec3& a, const glm::dvec3& b) { return glm::length(a - b) / glm::length(b); }

integrate_options estimator(translation_estimator e) {
  integrate_options o;
  o.translation = e;
  o.min_wall_distance = 1e-6f;  // the clamp is tested on its own; here the estimators are compared unclamped
  return o;
}

}  // namespace

TEST_CASE("integrate: a uniform sky gives pi L and zero gradients at every resolution", "[integrate]") {
  for (int n : {2, 16, 64, 512}) {
    hemicube_buffer buf;
    buf.resize(n);
    const glm::vec3 sky(0.7f, 1.3f, 2.0f);
    buf.fill_sky(sky);
    for (bool dbl : {false, true}) {
      integrate_options o;
      o.double_precision = dbl;
      o.directional = true;
      const irradiance_sample s = integrate(buf, o);
      INFO("N = " << n << (dbl ? " double" : " float"));
      // Tolerance: weights are exact in double and rounded to float (6e-8 relative each, random
      // signs); the float path sums a row of N <= 512 texels in 8 float lanes (worst case
      // (N/8) x 6e-8 = 4e-6) and adds rows in double. 1e-5 covers both with margin.
      for (int c = 0; c < 3; ++c) CHECK(std::fabs(s.irradiance[c] / (pi * sky[c]) - 1.0) < 1e-5);
      // Constant radiance: every wall has dL = 0 exactly, so g_t is exactly zero; g_r sums the
      // symmetric vector weights, zero up to their float rounding (1e-6 of pi L).
      for (std::size_t c = 0; c < 3; ++c) {
        CHECK(glm::length(s.translation_gradient[c]) == 0.0f);
        CHECK(glm::length(s.rotation_gradient[c]) < 1e-6 * pi * sky[int(c)]);
      }
      CHECK(std::isinf(s.harmonic_mean_distance));
      CHECK(std::isinf(s.min_distance));
      CHECK(s.backface_fraction == 0.0f);
      // Directional outputs, closed forms for a uniform sky over the upper hemisphere:
      // SH: Y00 * 2 pi L, Y10 * pi L (integral of z over the hemisphere), x and y terms 0.
      CHECK(s.sh_l1[0].x == Approx(0.282094791773878 * 2 * pi * sky.x).epsilon(1e-5));
      CHECK(s.sh_l1[2].x == Approx(0.488602511902920 * pi * sky.x).epsilon(1e-5));
      CHECK(std::fabs(s.sh_l1[1].x) < 1e-5f);
      CHECK(std::fabs(s.sh_l1[3].x) < 1e-5f);
    }
  }
}

TEST_CASE("integrate: Half-Life 2 basis irradiance under a uniform sky matches the tilted-plane view factor", "[integrate]") {
  // A plane tilted by alpha sees the upper-hemisphere sky with E = pi L (1 + cos alpha) / 2; the
  // HL2 vectors are tilted by acos(1/sqrt3). Only texels straddling the tilted horizon are
  // approximated (clamped vector weight); their projected weight bounds the error: ~2 x (2/N)
  // of pi at the horizon ring, i.e. < 2% at N = 64 and < 0.5% at N = 256.
  for (int n : {64, 256}) {
    hemicube_buffer buf;
    buf.resize(n);
    buf.fill_sky(glm::vec3(1.0f));
    integrate_options o;
    o.directional = true;
    const irradiance_sample s = integrate(buf, o);
    const double expected = pi * (1.0 + 1.0 / std::sqrt(3.0)) / 2.0;
    for (std::size_t k = 0; k < 3; ++k) CHECK(std::fabs(s.hl2[k].x / expected - 1.0) < (n == 64 ? 0.02 : 0.005));
  }
}

TEST_CASE("integrate: L1 SH band 1 of an unoccluded polygon is its vector irradiance, with or without g_r", "[integrate]") {
  // For radiance seen only in the upper hemisphere, the band-1 projection of L is
  // Y1 * integral of L w d omega = Y1 * Phi (the vector irradiance, Lambert's polygon formula),
  // in world order (y, z, x). The hemicube's vector solid angles are exact per texel, so only
  // the emitter's edge texels (partly covered) err: the same bound as E's (2% at N = 256 is ample:
  // the emitter spans ~150 texels across there).
  const closed_form_scene s = unoccluded_emitter();
  const hemicube_buffer buf = render(s, 256, s.position, s.normal);
  const glm::dvec3 phi = polygon_vector_irradiance({{-0.3, -0.2, 1.0}, {-0.3, 0.4, 1.0}, {0.5, 0.4, 1.0}, {0.5, -0.2, 1.0}},
                                                   s.position, 1.0);
  const double y1 = 0.488602511902920;
  for (bool gradients : {true, false})
    for (bool simd_kernels : {true, false}) {
      integrate_options o;
      o.directional = true;
      o.rotation_gradient = gradients;
      o.simd_kernels = simd_kernels;
      const irradiance_sample r = integrate(buf, o);
      INFO("rotation gradient " << gradients << ", simd kernels " << simd_kernels);
      const glm::dvec3 band1(r.sh_l1[3].x, r.sh_l1[1].x, r.sh_l1[2].x);  // (x, y, z) of red
      CHECK(glm::length(band1 / y1 - phi * double(s.tint.x)) < 0.02 * glm::length(phi));
    }
}

TEST_CASE("integrate: polygon emitter irradiance converges to Lambert's formula within the derived bound", "[integrate]") {
  const closed_form_scene s = unoccluded_emitter();
  const double e_ref = s.irradiance(s.position, s.normal);
  double previous_bound = 1e9;
  for (int n : {16, 64, 256}) {
    const irradiance_sample r = integrate(render(s, n, s.position, s.normal), estimator(translation_estimator::great_arc));
    const double err = std::fabs(r.irradiance.x - e_ref);
    // Bounds: every texel not cut by the emitter's outline is exact, each cut texel is off by at
    // most L x its projected solid angle (L = 1 here): the rigorous bound. The statistical bound
    // (boundary_stats) is the one that measures the error's size (~perimeter / area in texels,
    // over sqrt(cut texels)): 1.8% of E at N = 64 for this emitter of ~30 x 25 texels.
    const boundary_stats b = boundary_weights(s, n, s.position, s.normal, true);
    INFO("N = " << n << ": |E - E_ref| / E_ref = " << err / e_ref << ", rigorous bound " << b.sum / e_ref
                << ", statistical bound " << b.statistical() / e_ref);
    CHECK(err <= b.sum);
    CHECK(err <= b.statistical());
    if (n == 64) CHECK(err / e_ref < 0.02);
    CHECK(b.sum < 0.6 * previous_bound);  // the bound shrinks ~1/N: the error converges
    previous_bound = b.sum;
    // Channels scale with the emitter's tint (1, 0.5, 0.25) to float rounding.
    CHECK(r.irradiance.y == Approx(0.5 * r.irradiance.x).epsilon(1e-6));
    CHECK(r.irradiance.z == Approx(0.25 * r.irradiance.x).epsilon(1e-6));
  }
}

TEST_CASE("integrate: rotation gradient of an unoccluded polygon equals n x (vector irradiance)", "[integrate]") {
  // E(n) = n . Phi exactly for an unoccluded polygon, so g_r = n x Phi is exact. The hemicube's
  // g_r = n x sum L_i V_i differs only on texels cut by the outline: bound L x (sum of their
  // solid angles), since |n x w| <= 1.
  const closed_form_scene s = unoccluded_emitter();
  const std::vector<glm::dvec3> quad = {{-0.3, -0.2, 1.0}, {-0.3, 0.4, 1.0}, {0.5, 0.4, 1.0}, {0.5, -0.2, 1.0}};
  const glm::dvec3 expected = glm::cross(s.normal, polygon_vector_irradiance(quad, s.position, 1.0));
  for (int n : {64, 256}) {
    const irradiance_sample r = integrate(render(s, n, s.position, s.normal));
    const glm::dvec3 g(r.rotation_gradient[0]);
    const double bound = boundary_weight(s, n, s.position, s.normal, false);
    INFO("N = " << n << ": |g_r - ref| = " << glm::length(g - expected) << ", |ref| = " << glm::length(expected)
                << ", bound " << bound);
    CHECK(glm::length(g - expected) <= bound);
    CHECK(std::fabs(glm::dot(g, s.normal)) < 1e-6);  // in the tangent plane
    if (n == 256) CHECK(rel(g, expected) < 0.01);    // measured 0.14%
  }
}

TEST_CASE("integrate: translation gradients against central differences of the closed forms", "[integrate]") {
  // Reference: central differences of the exact E(x) (step 1e-5, error < 1e-9). N = 256 by the
  // reference ray caster, so only the integrator is measured. Measured relative errors at
  // N = 256 are in docs/integration.md (benchmarks/sweep_integrate); tolerances sit about 3x
  // above them: great_arc 1% (unoccluded), 3% (occluder edge), 15% (a wall seen edge-on: its
  // depth is sampled half a texel from the silhouette, the slow case of docs/integration.md), 3% (lit
  // room). The occlusion-aware estimators must beat the simple one near occluders.
  struct expect { closed_form_scene scene; double great_arc_tolerance; };
  for (const expect& e : {expect{unoccluded_emitter(), 0.01}, expect{occluded_emitter(), 0.03},
                          expect{beside_wall_under_sky(), 0.15}, expect{lit_room(), 0.03}}) {
    const closed_form_scene& s = e.scene;
    const glm::dvec3 ref = closed_form_translation_gradient(s);
    const hemicube_buffer buf = render(s, 256, s.position, s.normal);
    const double err_simple = rel(glm::dvec3(integrate(buf, estimator(translation_estimator::simple)).translation_gradient[0]), ref);
    const double err_class = rel(glm::dvec3(integrate(buf, estimator(translation_estimator::classified)).translation_gradient[0]), ref);
    const irradiance_sample arc = integrate(buf, estimator(translation_estimator::great_arc));
    const double err_arc = rel(glm::dvec3(arc.translation_gradient[0]), ref);
    INFO(s.name << ": simple " << err_simple << ", classified " << err_class << ", great_arc " << err_arc);
    CHECK(err_arc < e.great_arc_tolerance);
    CHECK(err_arc < err_class);
    CHECK(err_arc < err_simple);
    CHECK(std::fabs(glm::dot(glm::dvec3(arc.translation_gradient[0]), s.normal)) < 1e-6);  // tangent plane
    if (s.name == "emitter behind a near occluder edge" || s.name == "beside a tall wall under a sky")
      CHECK(err_simple > 0.5);  // the documented failure: no parallax, no occlusion
  }
}

TEST_CASE("integrate: the default estimator is great_arc", "[integrate]") {
  CHECK(integrate_options{}.translation == translation_estimator::great_arc);
}

TEST_CASE("integrate: rotation gradients against central differences of the closed forms", "[integrate]") {
  // E(x, n) in closed form, rotated by +-1e-5 rad: exact to ~1e-9. Hemicube at N = 256.
  // Tolerance: the discretisation bound of the rotation test above is ~1% of |g_r| at N = 256
  // for an emitter; with occluder edges and a room of many outlines, 3%.
  for (const closed_form_scene& s : {unoccluded_emitter(), occluded_emitter(), lit_room()}) {
    const glm::dvec3 ref = closed_form_rotation_gradient(s);
    const irradiance_sample r = integrate(render(s, 256, s.position, s.normal));
    INFO(s.name << ": |g_r - ref| / |ref| = " << rel(glm::dvec3(r.rotation_gradient[0]), ref));
    CHECK(rel(glm::dvec3(r.rotation_gradient[0]), ref) < 0.03);
  }
}

TEST_CASE("integrate: gradients against finite differences of re-rendered hemicubes", "[integrate]") {
  // The pipeline check the closed forms cannot give: E of hemicubes re-rendered (reference ray
  // caster, N = 256) at displaced points and rotated normals, each E averaged over 4 rolls of
  // the hemicube (discretisation noise ~0.1% of E per hemicube, measured, halved by 4 rolls).
  // Translation step h = 0.03 (the wall is 0.15 away): truncation ~(h/0.15)^2/6 = 0.7%, noise
  // ~5e-4 E x sqrt(2) / 2h = 1.2% of |g_t|. Rotation step a = 0.05 rad: truncation ~a^2/6, noise
  // ~1.5% of |g_r|. Tolerance 8% for both (the sum of the two, doubled).
  const closed_form_scene s = lit_room();
  const int n = 256, rolls = 4;
  auto e_avg = [&](const glm::dvec3& x, const glm::dvec3& normal) {
    double sum = 0.0;
    for (int k = 0; k < rolls; ++k) sum += integrate(render(s, n, x, normal, 0.3 + 1.5707963 * k)).irradiance.x;
    return sum / rolls;
  };
  const frame f = make_frame(glm::vec3(s.normal));
  const glm::dvec3 t(f.t), b(f.b), nn(f.n);
  const double h = 0.03, a = 0.05;
  const glm::dvec3 fd_t = (e_avg(s.position + h * t, nn) - e_avg(s.position - h * t, nn)) / (2 * h) * t +
                          (e_avg(s.position + h * b, nn) - e_avg(s.position - h * b, nn)) / (2 * h) * b;
  auto rot = [&](const glm::dvec3& axis, double angle) { return std::cos(angle) * nn + std::sin(angle) * axis; };
  const glm::dvec3 fd_r = (e_avg(s.position, rot(t, a)) - e_avg(s.position, rot(t, -a))) / (2 * a) * b -
                          (e_avg(s.position, rot(b, a)) - e_avg(s.position, rot(b, -a))) / (2 * a) * t;
  const hemicube_buffer buf = render(s, n, s.position, s.normal);
  const irradiance_sample arc = integrate(buf, estimator(translation_estimator::great_arc));
  const glm::dvec3 simple(integrate(buf, estimator(translation_estimator::simple)).translation_gradient[0]);
  const glm::dvec3 gt(arc.translation_gradient[0]), gr(arc.rotation_gradient[0]);
  INFO("g_t: FD " << fd_t.x << " " << fd_t.y << ", great_arc " << gt.x << " " << gt.y << ", simple " << simple.x << " " << simple.y);
  INFO("g_r: FD " << fd_r.x << " " << fd_r.y << ", hemicube " << gr.x << " " << gr.y);
  CHECK(rel(gt, fd_t) < 0.08);
  CHECK(rel(gt, fd_t) < rel(simple, fd_t));
  CHECK(rel(gr, fd_r) < 0.08);
}

TEST_CASE("integrate: float and double accumulation agree (both float kernels)", "[integrate]") {
  const closed_form_scene s = lit_room();
  hemicube_buffer buf = render(s, 128, s.position, s.normal);
  // Some back-face texels (every seventh), so the back-face sums are exercised too; and N = 6
  // (108 texels, not a multiple of 8) for the kernels' tails.
  for (std::size_t i = 0; i < buf.texel_count(); i += 7) buf.flags[i] = texel_back_face;
  const hemicube_buffer small = render(s, 6, s.position, s.normal);
  for (const hemicube_buffer* b : {static_cast<const hemicube_buffer*>(&buf), &small}) {
    for (bool simd_kernels : {true, false}) {
      integrate_options of, od;
      od.double_precision = true;
      of.simd_kernels = simd_kernels;
      of.directional = od.directional = true;
      const irradiance_sample a = integrate(*b, of), d = integrate(*b, od);
      INFO("N " << b->resolution << ", simd kernels " << simd_kernels);
      // Float lanes over blocks of 1024 texels: relative error ~ (1024/8) x 6e-8 ~ 1e-5 per sum at
      // worst, ~1e-6 typically; the gradients are sums of signed terms that cancel to ~10% of their
      // magnitude, so 1e-4.
      CHECK(a.irradiance.x == Approx(d.irradiance.x).epsilon(1e-5));
      CHECK(a.harmonic_mean_distance == Approx(d.harmonic_mean_distance).epsilon(1e-5));
      CHECK(a.backface_fraction == Approx(d.backface_fraction).epsilon(1e-5));
      CHECK(a.min_distance == d.min_distance);
      CHECK(glm::length(a.translation_gradient[0] - d.translation_gradient[0]) <
            1e-4f * glm::length(d.translation_gradient[0]));
      CHECK(glm::length(a.rotation_gradient[0] - d.rotation_gradient[0]) < 1e-4f * glm::length(d.rotation_gradient[0]));
      CHECK(a.hl2[0].x == Approx(d.hl2[0].x).epsilon(1e-5));
    }
  }
  // The back-face fraction itself: the weight of the flagged texels (1 in 7, spread evenly).
  integrate_options od;
  od.double_precision = true;
  CHECK(integrate(buf, od).backface_fraction == Approx(1.0 / 7.0).epsilon(0.02));
}

TEST_CASE("integrate: black texel groups are skipped without losing a wall", "[integrate]") {
  // The AVX2 kernels skip groups of eight texels whose radiance is all zero (and whose right and
  // upper neighbours are too). One lit texel at a time, at every position (every lane of a group,
  // group ends, row and face ends, N = 30 whose rows are not a multiple of 8, N = 6 and 10 with a
  // tail of 4, which the last upper walls of N = 10 read): a skipped wall would drop about a
  // quarter of the texel's gradient. Reference: the
  // double path, which has no skip. One texel's walls are four terms, so float and double agree
  // to rounding: 1e-5 of the gradient's size, plus 1e-6 of the largest single-texel gradient of
  // that N for texels whose opposite walls cancel (their float sum keeps ~1e-7 of the terms).
  const closed_form_scene s = lit_room();
  for (int n : {6, 10, 16, 30}) {
    hemicube_buffer buf = render(s, n, s.position, s.normal);
    std::fill(buf.radiance.begin(), buf.radiance.end(), 0.0f);
    integrate_options of, od;
    od.double_precision = true;
    hemicube_integrator fast(n, of), ref(n, od);
    std::vector<irradiance_sample> a, d;
    float largest = 0.0f;
    for (std::size_t i = 0; i < buf.texel_count(); ++i) {
      for (int c = 0; c < 3; ++c) buf.channel(c)[i] = 1.0f + 0.5f * static_cast<float>(c);
      a.push_back(fast.integrate(buf));
      d.push_back(ref.integrate(buf));
      for (int c = 0; c < 3; ++c) buf.channel(c)[i] = 0.0f;
      largest = std::max(largest, glm::length(d.back().translation_gradient[2]));
    }
    REQUIRE(largest > 0.0f);
    for (std::size_t i = 0; i < buf.texel_count(); ++i) {
      INFO("N " << n << ", lit texel " << i);
      CHECK(a[i].irradiance.z == Approx(d[i].irradiance.z).epsilon(1e-6));
      for (std::size_t c = 0; c < 3; ++c) {
        const float size = glm::length(d[i].translation_gradient[c]);
        CHECK(glm::length(a[i].translation_gradient[c] - d[i].translation_gradient[c]) <=
              1e-5f * size + 1e-6f * largest);
      }
    }
  }
}

TEST_CASE("integrate: a reused integrator gives the same bits whether or not it maps black groups", "[integrate]") {
  // hemicube_integrator maps black groups only while its hemicubes have many (a speed heuristic:
  // skipping them never changes a sum), so a lit hemicube after a lit one takes the unmapped
  // kernels, and one with black regions the mapped ones. Both must give exactly what a fresh
  // integrator (which maps) gives.
  const closed_form_scene s = lit_room();
  const hemicube_buffer lit = render(s, 64, s.position, s.normal);
  hemicube_buffer half = lit;  // the lower half of the texels black: many black groups
  for (int c = 0; c < 3; ++c) std::fill(half.channel(c), half.channel(c) + half.texel_count() / 2, 0.0f);
  hemicube_buffer few = lit;  // 1/20 of the texels black: mapped, but too few to map the next one
  for (int c = 0; c < 3; ++c) std::fill(few.channel(c), few.channel(c) + few.texel_count() / 20, 0.0f);
  hemicube_integrator reused(64);
  const hemicube_buffer* const dark = &half;
  const hemicube_buffer* const some = &few;
  for (const hemicube_buffer* b : {some, &lit, &lit, dark, dark, &lit, some, &lit}) {
    const irradiance_sample a = reused.integrate(*b), f = integrate(*b);
    CHECK(a.irradiance == f.irradiance);
    CHECK(a.harmonic_mean_distance == f.harmonic_mean_distance);
    for (std::size_t c = 0; c < 3; ++c) {
      CHECK(a.translation_gradient[c] == f.translation_gradient[c]);
      CHECK(a.rotation_gradient[c] == f.rotation_gradient[c]);
    }
  }
}

TEST_CASE("integrate: the result does not depend on the hemicube's roll beyond the discretisation bound", "[integrate]") {
  const closed_form_scene s = unoccluded_emitter();
  const int n = 64;
  const double e_ref = s.irradiance(s.position, s.normal);
  for (int k = 0; k < 6; ++k) {
    const double roll = 0.37 * k;  // radians
    const irradiance_sample r = integrate(render(s, n, s.position, s.normal, roll));
    const double bound = boundary_weights(s, n, s.position, s.normal, true, roll).statistical();
    INFO("roll " << roll << ": E " << r.irradiance.x << " vs " << e_ref << ", statistical bound " << bound);
    CHECK(std::fabs(r.irradiance.x - e_ref) <= bound);
  }
}

TEST_CASE("integrate: harmonic mean distance under a plane is 3h/2", "[integrate]") {
  // Point at height h under a large plane facing it: 1/R = (1/pi) int cos^2/h = 2/(3h). The
  // plane is 2e4 h wide, so only directions within 1e-4 of the horizon miss it (< 1e-8 of the
  // weight). Texel-centre sampling of cos(theta)/h: relative error ~ (2/N)^2 / 6 ~ 2e-4 at N = 64.
  std::vector<ref_triangle> tris;
  const double h = 0.8, w = 1e4 * h;
  add_quad(tris, {-w, -w, h}, {-w, w, h}, {w, w, h}, {w, -w, h}, glm::vec3(1.0f));
  const irradiance_sample r = integrate(raycast_hemicube(tris, glm::vec3(0.0f), {0, 0, 0}, make_frame({0, 0, 1}), 64));
  CHECK(r.harmonic_mean_distance == Approx(1.5 * h).epsilon(1e-3));
  CHECK(r.min_distance == Approx(h).epsilon(1e-3));  // the texels nearest the zenith
  CHECK(r.irradiance.x == Approx(pi).epsilon(1e-3));  // fills the hemisphere but for the horizon ring
}

TEST_CASE("integrate: inside an outward-facing box every texel sees a back face", "[integrate]") {
  std::vector<ref_triangle> tris;
  const double a = 1.0;
  // Outward-facing unit cube faces (CCW seen from outside).
  add_quad(tris, {-a, -a, a}, {a, -a, a}, {a, a, a}, {-a, a, a}, glm::vec3(1.0f));      // +z
  add_quad(tris, {-a, -a, -a}, {-a, a, -a}, {a, a, -a}, {a, -a, -a}, glm::vec3(1.0f));  // -z
  add_quad(tris, {a, -a, -a}, {a, a, -a}, {a, a, a}, {a, -a, a}, glm::vec3(1.0f));      // +x
  add_quad(tris, {-a, -a, -a}, {-a, -a, a}, {-a, a, a}, {-a, a, -a}, glm::vec3(1.0f));  // -x
  add_quad(tris, {-a, a, -a}, {-a, a, a}, {a, a, a}, {a, a, -a}, glm::vec3(1.0f));      // +y
  add_quad(tris, {-a, -a, -a}, {a, -a, -a}, {a, -a, a}, {-a, -a, a}, glm::vec3(1.0f));  // -y
  const irradiance_sample r = integrate(raycast_hemicube(tris, glm::vec3(1.0f), {0.2, -0.1, 0.3}, make_frame({0, 0, 1}), 32));
  CHECK(r.backface_fraction == Approx(1.0).epsilon(1e-6));
  CHECK(r.irradiance.x == 0.0f);
  CHECK(r.min_distance == Approx(0.7).epsilon(0.01));  // the +z face is 0.7 away, sampled at texel centres
}

TEST_CASE("integrate: geometry at the near plane gives finite, clamped gradients", "[integrate]") {
  // The occluded-emitter scene with the occluder edge 1e-6 above the point: walls along the
  // edge are at distance ~1e-6, which unclamped gives |g_t| ~ 1e6 E. The automatic clamp (wall
  // distance >= 0.1 x harmonic mean R) bounds |g_t| by 10 / R x (sum over the walls of the
  // silhouette of |dL| x coefficient); a silhouette is at most a great semicircle, whose
  // staircase of walls has total coefficient <= sqrt(2) pi, so |g_t| R <= 10 sqrt(2) pi L_max.
  closed_form_scene s = occluded_emitter();
  for (ref_triangle& t : s.tris)
    if (t.radiance.x == 0.0f) t.a.z = t.b.z = t.c.z = 1e-6;
  const hemicube_buffer buf = render(s, 64, s.position, s.normal);
  const irradiance_sample r = integrate(buf);  // default options: automatic clamp
  const float g = glm::length(r.translation_gradient[0]);
  INFO("|g_t| = " << g << ", R = " << r.harmonic_mean_distance << ", E = " << r.irradiance.x);
  CHECK(std::isfinite(g));
  CHECK(std::isfinite(glm::length(r.rotation_gradient[0])));
  CHECK(g * r.harmonic_mean_distance <= 10.0 * std::sqrt(2.0) * pi * 1.0);
  // With an explicit floor the bound follows the floor instead.
  integrate_options o;
  o.min_wall_distance = 0.05f;
  const float g2 = glm::length(integrate(buf, o).translation_gradient[0]);
  CHECK(g2 * 0.05 <= std::sqrt(2.0) * pi * 1.0);
}

TEST_CASE("integrate: bad input gets a clear error", "[integrate]") {
  hemicube_buffer buf;
  buf.resize(16);
  buf.fill_sky(glm::vec3(1.0f));
  hemicube_integrator integrator(32);
  CHECK_THROWS_WITH(integrator.integrate(buf), Catch::Contains("buffer has resolution 16") && Catch::Contains("expects 32"));
  buf.distance.pop_back();
  hemicube_integrator i16(16);
  CHECK_THROWS_AS(i16.integrate(buf), error);
  integrate_options o;
  o.min_wall_distance = -1.0f;
  CHECK_THROWS_WITH(hemicube_integrator(16, o), Catch::Contains("min_wall_distance"));
  o.min_wall_distance = NAN;
  CHECK_THROWS_WITH(hemicube_integrator(16, o), Catch::Contains("min_wall_distance"));
  CHECK_THROWS_WITH(hemicube_integrator(15), Catch::Contains("resolution 15"));
  hemicube_buffer empty;
  CHECK_THROWS_AS(integrate(empty), error);
}

TEST_CASE("integrate: an emitter seen edge-on: the translation gradient's error falls as 1 / (sliver height in texels)",
          "[integrate]") {
  // The point is on a wall just under the plane of an emitter (emitter_seen_edge_on): the
  // emitter's outline is a sliver h = (depth / 0.05) / (pi/2 / N) texels tall at its near edge.
  // great_arc takes one distance per texel, the centre's, where the depth across a texel of a
  // plane seen at a grazing angle varies most, so its gradient is low by a fraction of about
  // 1.6 / h (measured 1.5 / h to 2.1 / h over depth 1-20 mm, N = 64-512: docs/integration.md).
  // Reference: central differences of the closed form. The tolerance, 2.5 / h, is the documented
  // bound; below h = 3 texels the gradient is not estimated at all (0-50% of it).
  for (double depth : {0.001, 0.002, 0.005, 0.01, 0.02})
    for (int n : {64, 256, 512}) {
      const double h = depth / 0.05 / (0.5 * pi / n);
      if (h < 3.0) continue;
      const closed_form_scene s = emitter_seen_edge_on(depth);
      const glm::dvec3 ref = closed_form_translation_gradient(s);
      const irradiance_sample arc = integrate(render(s, n, s.position, s.normal), estimator(translation_estimator::great_arc));
      const double err = rel(glm::dvec3(arc.translation_gradient[0]), ref);
      INFO("depth " << depth << ", N = " << n << ", h = " << h << " texels: relative error " << err << ", x h = " << err * h);
      CHECK(err * h < 2.5);
      CHECK(arc.translation_gradient[0].y / ref.y > 0.0);  // the right sign: E grows with the depth
    }
}


TEST_CASE("integrate: extrapolate_wall_depth: edge-on emitters and walls against the closed forms", "[integrate]") {
  // The same closed forms and reference (central differences of the exact E) as the two tests
  // above, with the wall depth extrapolated half a texel. Measured (great_arc, relative error
  // of g_t): emitter seen edge-on 1 mm under its plane, N = 512: 25% -> 4.0%; 2 mm, N = 256:
  // 23% -> 0.97%; 10 mm, N = 64: 19% -> 0.25%; a wall seen edge-on under a sky, N = 256: 3.8% ->
  // 0.13%, N = 64: 17% -> 2.5%; the unoccluded, occluder-edge and lit-room scenes within 0.1% of
  // their unextrapolated errors or better. Tolerances: 3 x the measured error, at least 0.5%.
  struct expect { closed_form_scene scene; int n; double tolerance; };
  for (const expect& e : {expect{emitter_seen_edge_on(0.001), 512, 0.12}, expect{emitter_seen_edge_on(0.002), 256, 0.03},
                          expect{emitter_seen_edge_on(0.01), 64, 0.0075}, expect{beside_wall_under_sky(), 256, 0.005},
                          expect{beside_wall_under_sky(), 64, 0.075}, expect{unoccluded_emitter(), 256, 0.015},
                          expect{occluded_emitter(), 256, 0.025}, expect{lit_room(), 256, 0.055}}) {
    const closed_form_scene& s = e.scene;
    const glm::dvec3 ref = closed_form_translation_gradient(s);
    const hemicube_buffer buf = render(s, e.n, s.position, s.normal);
    integrate_options o = estimator(translation_estimator::great_arc);
    const double before = rel(glm::dvec3(integrate(buf, o).translation_gradient[0]), ref);
    o.extrapolate_wall_depth = true;
    const irradiance_sample ext = integrate(buf, o);
    const double after = rel(glm::dvec3(ext.translation_gradient[0]), ref);
    o.simd_kernels = false;  // the portable loops against the AVX2 kernels (where the CPU has them)
    const double after_portable = rel(glm::dvec3(integrate(buf, o).translation_gradient[0]), ref);
    CHECK(std::fabs(after_portable - after) < 1e-4);
    o.double_precision = true;
    const double after_double = rel(glm::dvec3(integrate(buf, o).translation_gradient[0]), ref);
    INFO(s.name << ", N = " << e.n << ": centre depth " << before << ", extrapolated " << after << " (double "
                << after_double << ")");
    CHECK(after < e.tolerance);
    CHECK(after <= before + 0.001);
    CHECK(std::fabs(after_double - after) < 1e-3);  // float and double accumulation agree
    CHECK(std::fabs(glm::dot(glm::dvec3(ext.translation_gradient[0]), s.normal)) < 1e-6);  // tangent plane
  }
}

TEST_CASE("integrate: hemicubes with exact edge coverage give the closed forms' E and gradients", "[integrate]") {
  // The closed-form scenes rendered by the rasterizer (not the reference ray caster), with and
  // without raster_options::edge_coverage, at N = 64 and 256 (rolled 0.3 rad). Blended edge
  // texels make E exact up to second-order terms and the rotation gradient exact up to the
  // texels' vector solid angles; the translation gradient spreads each edge's step over the
  // walls on both sides of the texels it crosses, at the nearest partial surface's distance.
  // Measured (edge / point): E 5e-8-3e-4 / 5e-5-2.4e-2; g_r 7e-6-3e-4 / 8e-5-2.5e-2; g_t at
  // N = 256: unoccluded 0.16% / 0.65%, occluder edge 0.21% / 0.94%, room 1.9% / 1.7%.
  // Tolerances: E 0.1%; g_r as the ray-cast test above (3%) and no worse than point sampling
  // + 0.5%; g_t within 1.25x point sampling's + 0.5%, and at N = 256 the ray-cast test's
  // great_arc tolerances (1% unoccluded, 3% occluder edge, 3% room).
  struct expect { closed_form_scene scene; double g_t_tolerance; };
  for (const expect& e : {expect{unoccluded_emitter(), 0.01}, expect{occluded_emitter(), 0.03}, expect{lit_room(), 0.03}}) {
    const closed_form_scene& s = e.scene;
    scene_mesh m;
    for (const ref_triangle& t : s.tris)
      m.add_triangle(glm::vec3(t.a), glm::vec3(t.b), glm::vec3(t.c), material{t.radiance, glm::vec3(0.0f), t.two_sided});
    m.sky_radiance = s.sky;
    const auto sc = scene::create(m.desc());
    const double e_ref = s.irradiance(s.position, s.normal);
    const glm::dvec3 gr_ref = closed_form_rotation_gradient(s), gt_ref = closed_form_translation_gradient(s);
    for (const int n : {64, 256}) {
      double err[2][3];
      for (int mode = 0; mode < 2; ++mode) {
        raster_options o;
        o.edge_coverage = mode == 1;
        hemicube_rasterizer r(sc, o);
        hemicube_buffer buf;
        r.render(glm::vec3(s.position), rolled_frame(s.normal, 0.3), n, buf);
        const irradiance_sample out = integrate(buf);
        err[mode][0] = std::fabs(out.irradiance.x - e_ref) / e_ref;
        err[mode][1] = rel(glm::dvec3(out.rotation_gradient[0]), gr_ref);
        err[mode][2] = rel(glm::dvec3(out.translation_gradient[0]), gt_ref);
      }
      INFO(s.name << ", N = " << n << ": point E " << err[0][0] << " g_r " << err[0][1] << " g_t " << err[0][2]
                  << "; edge E " << err[1][0] << " g_r " << err[1][1] << " g_t " << err[1][2]);
      CHECK(err[1][0] <= 1e-3);
      CHECK(err[1][1] <= 0.03);
      CHECK(err[1][1] <= err[0][1] + 0.005);
      CHECK(err[1][2] <= 1.25 * err[0][2] + 0.005);
      if (n == 256) CHECK(err[1][2] <= e.g_t_tolerance);
    }
  }
}
