// Tests of bake.hpp: exact UV coverage against analytic and supersampled references, the overlap
// rule, a closed box lit by an emissive ceiling against Lambert's formula, the white furnace
// against its geometric series, dilation, indirect-only output, determinism across thread
// counts, cancellation and bad input; lights: a hard sun against E cos theta (with its SH and HL2
// terms), an occluder's umbra and the shadow mask, a point-lit furnace against the geometric
// series, determinism and bad lights.
#include "hemilight/bake.hpp"
#include "hemilight/cubemap.hpp"
#include "hemilight/reference_scenes.hpp"

#include "raycast_reference.hpp"
#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>

using namespace hemilight;

namespace {

constexpr double pi = 3.14159265358979323846;

using test::uv_mesh;

// The Cornell box with 32 x 32 chart UVs and small bake options (N = 16, 2 bounces): fast.
struct small_cornell {
  scene_mesh mesh = cornell_box();
  bake_options options;
  small_cornell() {
    generate_lightmap_uvs(mesh, 32, 2);
    options.width = options.height = 32;
    options.sampler.resolution = 16;
    options.bounces = 2;
  }
};

bake_input input_of(const scene_mesh& m) {
  bake_input in;
  in.scene = m.desc();
  return in;
}

// Coverage by supersampling: the fraction of an s x s grid of points in the texel that lie in
// the triangle, and their mean (texel units). Independent of the clipper.
std::pair<double, glm::dvec2> supersample(const glm::dvec2 (&t)[3], int x, int y, int s) {
  int in = 0;
  glm::dvec2 sum(0.0);
  for (int j = 0; j < s; ++j)
    for (int i = 0; i < s; ++i) {
      const glm::dvec2 p(x + (i + 0.5) / s, y + (j + 0.5) / s);
      double d[3];
      for (int k = 0; k < 3; ++k) {
        const glm::dvec2 a = t[k], b = t[(k + 1) % 3];
        d[k] = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
      }
      if ((d[0] >= 0 && d[1] >= 0 && d[2] >= 0) || (d[0] <= 0 && d[1] <= 0 && d[2] <= 0)) {
        ++in;
        sum += p;
      }
    }
  return {double(in) / (s * s), in ? sum / double(in) : glm::dvec2(0.0)};
}

// A closed 1 x 1 x 1 room (faces inward), floor y = 0, each face its own material.
scene_mesh closed_room(const material& floor_walls, const material& ceiling, int grid = 1) {
  scene_mesh m;
  const glm::vec3 p[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  // Counter-clockwise seen from inside.
  m.add_grid(p[0], p[4], p[5], p[1], grid, grid, floor_walls);    // floor (y = 0), normal +y
  m.add_grid(p[3], p[2], p[6], p[7], grid, grid, ceiling);        // ceiling (y = 1), normal -y
  m.add_grid(p[0], p[1], p[2], p[3], grid, grid, floor_walls);    // z = 0, normal +z
  m.add_grid(p[4], p[7], p[6], p[5], grid, grid, floor_walls);    // z = 1, normal -z
  m.add_grid(p[0], p[3], p[7], p[4], grid, grid, floor_walls);    // x = 0, normal +x
  m.add_grid(p[1], p[5], p[6], p[2], grid, grid, floor_walls);    // x = 1, normal -x
  return m;
}

}  // namespace

TEST_CASE("Coverage of a unit quad mapped to the whole lightmap is full with texel-centre centroids", "[bake]") {
  uv_mesh m;
  m.add({0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0}, {1, 0}, {1, 1});
  m.add({0, 0, 0}, {1, 0, 1}, {0, 0, 1}, {0, 0}, {1, 1}, {0, 1});
  const int w = 8, h = 4;
  const lightmap_samples s = compute_lightmap_samples(m.input(), w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t k = std::size_t(y * w + x);
      // Float rounding of the summed clipped areas only.
      CHECK(s.coverage[k] == Approx(1.0).margin(1e-6));
      CHECK(s.centroid[k].x == Approx((x + 0.5) / w).margin(1e-6));
      CHECK(s.centroid[k].y == Approx((y + 0.5) / h).margin(1e-6));
      // The quad maps u to x and v to z: the 3D sample is the texel centre's point.
      CHECK(s.position[k].x == Approx((x + 0.5) / w).margin(1e-6));
      CHECK(s.position[k].z == Approx((y + 0.5) / h).margin(1e-6));
      // Face normal of (a, b, c) = (1,0,0) x (1,0,1) = (0,-1,0).
      CHECK(s.normal[k].y == Approx(-1.0).margin(1e-6));
    }
  CHECK(s.overlapping_texels == 0);
}

TEST_CASE("Coverage of a triangle matches the analytic and supersampled area per texel", "[bake]") {
  SECTION("a right triangle on the texel grid: texels are full, half or empty") {
    uv_mesh m;
    m.add({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0}, {1, 0}, {0, 1});
    const int n = 8;
    const lightmap_samples s = compute_lightmap_samples(m.input(), n, n);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        // Region u + v <= 8 (texel units): full below the diagonal, half on it, none above.
        const double expected = x + y + 2 <= n ? 1.0 : (x + y + 1 == n ? 0.5 : 0.0);
        CHECK(s.coverage[std::size_t(y * n + x)] == Approx(expected).margin(1e-6));
        if (x + y + 1 == n) {
          // Centroid of the half texel below the diagonal: 1/3 of the way from the corner (x, y).
          CHECK(s.centroid[std::size_t(y * n + x)].x * n == Approx(x + 1.0 / 3.0).margin(1e-5));
          CHECK(s.centroid[std::size_t(y * n + x)].y * n == Approx(y + 1.0 / 3.0).margin(1e-5));
        }
      }
  }
  SECTION("a general triangle against 256 x 256 supersampling") {
    const glm::dvec2 t[3] = {{0.7, 1.3}, {13.2, 4.9}, {5.1, 14.6}};  // texel units in a 16 x 16 map
    const int n = 16;
    uv_mesh m;
    m.add({0, 0, 0}, {1, 0, 0}, {0, 0, 1}, glm::vec2(t[0] / double(n)), glm::vec2(t[1] / double(n)), glm::vec2(t[2] / double(n)));
    const lightmap_samples s = compute_lightmap_samples(m.input(), n, n);
    double total = 0.0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const auto [ref, ref_c] = supersample(t, x, y, 256);
        const float cov = s.coverage[std::size_t(y * n + x)];
        total += cov;
        // Supersampling error: at most about (edge length in the texel) / 256 <= 1.5 / 256.
        CHECK(cov == Approx(ref).margin(0.006));
        if (ref > 0.05) {
          // Centroid of the covered part; supersampled mean, error ~ 1/256 / coverage.
          CHECK(s.centroid[std::size_t(y * n + x)].x * n == Approx(ref_c.x).margin(0.02));
          CHECK(s.centroid[std::size_t(y * n + x)].y * n == Approx(ref_c.y).margin(0.02));
        }
      }
    // Exact conservation: the clipped areas sum to the triangle's area (float rounding).
    const double area = 0.5 * std::fabs((t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x));
    CHECK(total == Approx(area).epsilon(1e-5));
  }
  SECTION("clip_triangle_to_texel of a triangle enclosing the texel is the whole texel") {
    const texel_clip c = clip_triangle_to_texel({-10, -10}, {30, -10}, {-10, 30}, 3, 4);
    CHECK(c.area == Approx(1.0f).margin(1e-6));
    CHECK(c.centroid.x == Approx(3.5f).margin(1e-5));
    CHECK(c.centroid.y == Approx(4.5f).margin(1e-5));
    const texel_clip none = clip_triangle_to_texel({0, 0}, {1, 0}, {0, 1}, 5, 5);
    CHECK(none.area == 0.0f);
  }
}

TEST_CASE("Overlap rule: the triangle with the largest covered area owns the texel and ties go to the lower index", "[bake]") {
  const int n = 4;
  SECTION("largest area wins") {
    uv_mesh m;
    // Triangle 0 covers half of texel (0, 0); triangle 1 (index higher) covers all of it.
    m.add({0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0}, {0.25f, 0}, {0, 0.25f});
    m.add({0, 1, 0}, {1, 1, 0}, {0, 1, 1}, {0, 0}, {1, 0}, {0, 1});
    const lightmap_samples s = compute_lightmap_samples(m.input(), n, n);
    CHECK(s.owner[0] == 1u);
    CHECK(s.sample_triangle[0] == 1u);
    CHECK(s.position[0].y == 1.0f);  // the sample lies on triangle 1 (y = 1)
    CHECK(s.overlapping_texels >= 1);
    CHECK(s.coverage[0] == 1.0f);    // clamped
  }
  SECTION("equal areas: the lower index wins") {
    uv_mesh m;
    m.add({0, 2, 0}, {1, 2, 0}, {0, 2, 1}, {0, 0}, {1, 0}, {0, 1});
    m.add({0, 1, 0}, {1, 1, 0}, {0, 1, 1}, {0, 0}, {1, 0}, {0, 1});
    const lightmap_samples s = compute_lightmap_samples(m.input(), n, n);
    for (std::size_t k = 0; k < s.owner.size(); ++k)
      if (s.coverage[k] > 0.0f) CHECK(s.owner[k] == 0u);
    CHECK(s.position[0].y == 2.0f);
  }
}

TEST_CASE("Closed box lit by an emissive ceiling: floor irradiance matches Lambert's formula", "[bake]") {
  material black;  // albedo 0: no bounces
  material light;
  light.emission = glm::vec3(1.0f);
  scene_mesh m = closed_room(black, light);
  generate_lightmap_uvs(m, 64, 2);
  bake_options o;
  o.width = o.height = 64;
  o.sampler.resolution = 32;
  o.cache.error_threshold = 0.1f;
  o.thread_count = 2;
  const bake_result r = bake_lightmap(input_of(m), o);
  const lightmap_samples s = compute_lightmap_samples(input_of(m), 64, 64);
  const std::vector<glm::dvec3> ceiling = {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}};
  double sum_sq = 0.0, sum_ref = 0.0, worst = 0.0;
  int count = 0;
  for (std::size_t k = 0; k < s.owner.size(); ++k) {
    if (!r.sampled[k] || s.normal[k].y < 0.99f) continue;  // floor texels only
    const double ref = test::polygon_vector_irradiance(ceiling, glm::dvec3(s.position[k]), 1.0).y;  // E = n . Phi, n = +y
    const double got = r.irradiance.pixels[3 * k + 1];
    sum_sq += (got - ref) * (got - ref);
    sum_ref += ref * ref;
    worst = std::max(worst, std::fabs(got - ref) / ref);
    ++count;
  }
  REQUIRE(count > 200);
  const double rms = std::sqrt(sum_sq / sum_ref);
  INFO("floor texels " << count << ", relative RMS error " << rms << ", worst " << worst);
  // The cache interpolates within about a (0.1) of the hemicube value; the hemicube at N = 32
  // adds < 1% (exact weights, only texel-centre discretisation of the emitter's edges).
  CHECK(rms < 0.02);
  CHECK(worst < 0.1);
}

TEST_CASE("White furnace: bounces converge along the geometric series and indirect-only keeps the rest", "[bake]") {
  const float a = 0.5f;
  material m;
  m.albedo = glm::vec3(a);
  m.emission = glm::vec3(1.0f);
  scene_mesh room = closed_room(m, m, 2);
  generate_lightmap_uvs(room, 32, 2);
  bake_options o;
  o.width = o.height = 32;
  o.sampler.resolution = 16;
  o.thread_count = 2;
  for (int bounces = 1; bounces <= 4; ++bounces) {
    o.bounces = bounces;
    // Closed form: pass k sees radiance L_e (1 + a + ... + a^(k-1)) everywhere, E = pi times that.
    double series = 0.0;
    for (int j = 0; j < bounces; ++j) series += std::pow(double(a), j);
    for (bool indirect : {false, true}) {
      o.indirect_only = indirect;
      const bake_result r = bake_lightmap(input_of(room), o);
      const double expected = pi * (indirect ? series - 1.0 : series);
      double worst = 0.0;
      for (std::size_t k = 0; k < r.sampled.size(); ++k)
        if (r.sampled[k])
          for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(r.irradiance.pixels[3 * k + std::size_t(c)] - expected));
      INFO("bounces " << bounces << (indirect ? " indirect only" : " full") << ": worst |E - closed form| " << worst);
      // The room is closed and uniform: every hemicube texel sees the same radiance, so only the
      // float sums of the weights (pi to ~1e-6 relative) and float rounding of the texture
      // values remain (measured < 1e-6): 1e-5 pi.
      CHECK(worst < 1e-5 * pi);
    }
  }
}

TEST_CASE("Dilation grows charts ring by ring with the mean of filled neighbours", "[bake]") {
  image img = image::make(5, 5, 3, 0.0f);
  std::vector<std::uint8_t> filled(25, 0);
  img.at(0, 2)[0] = 2.0f;
  filled[2 * 5 + 0] = 1;
  img.at(4, 2)[0] = 4.0f;
  filled[2 * 5 + 4] = 1;
  CHECK(dilate(img, filled, 1) == 10u);  // 5 texels around each of the two
  CHECK(img.at(1, 2)[0] == 2.0f);
  CHECK(img.at(3, 1)[0] == 4.0f);
  CHECK(filled[2 * 5 + 2] == 0);
  CHECK(dilate(img, filled, 1) == 13u);  // the rest: the middle column and the four corners
  CHECK(img.at(2, 2)[0] == Approx(3.0f));  // mean of 2 and 4 (three filled neighbours each side)
  CHECK(img.at(0, 0)[0] == Approx(2.0f));  // its filled neighbours were all 2
  CHECK(dilate(img, filled, -1) == 0u);   // nothing left
  std::vector<std::uint8_t> wrong(3, 0);
  CHECK_THROWS_AS(dilate(img, wrong, 1), error);

  SECTION("a bake leaves no black texel next to a chart") {
    material white;
    white.albedo = glm::vec3(0.5f);
    white.emission = glm::vec3(1.0f);
    scene_mesh room = closed_room(white, white);
    generate_lightmap_uvs(room, 32, 2);
    bake_options o;
    o.width = o.height = 32;
    o.sampler.resolution = 16;
    o.dilation = 2;
    const bake_result r = bake_lightmap(input_of(room), o);
    CHECK(r.stats.dilated_texels > 0);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        bool near_sample = false;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx >= 0 && ny >= 0 && nx < 32 && ny < 32 && r.sampled[std::size_t(ny * 32 + nx)]) near_sample = true;
          }
        // Within 2 rings of a chart every texel holds the uniform value pi.
        if (near_sample) CHECK(r.irradiance.at(x, y)[0] == Approx(pi).epsilon(1e-4));
      }
  }
}

TEST_CASE("Texels inside geometry are filled from valid texels of their own chart, never across the padding", "[bake][leaks]") {
  // A 32² map with three charts two texels apart: F, a floor under a bright emitter (u texels
  // 1-15); G, a quad inside a closed box (u 17-31, v 1-15): every sample invalid; H, a quad half
  // inside another box (u 17-31, v 17-31), its invalid half next to F in the atlas, 3 texels from
  // F's chart and 7 from its own valid texels. The emitter and the boxes have no texels (zero UV
  // area: they occlude and are seen). Sky 1.
  scene_mesh m;
  const material grey{glm::vec3(0.0f), glm::vec3(0.5f), false}, lamp{glm::vec3(60.0f), glm::vec3(0.5f), false};
  // A quad a, b, c, d (counter-clockwise from its front) with UVs ua, ub, uc, ud.
  const auto quad = [&m](std::array<glm::vec3, 4> p, std::array<glm::vec2, 4> uv, const material& mat) {
    const auto base = std::uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), p.begin(), p.end());
    m.lightmap_uvs.insert(m.lightmap_uvs.end(), uv.begin(), uv.end());
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    m.materials.insert(m.materials.end(), {mat, mat});
  };
  // A floor facing up over [x0, x1] x [z0, z1], u along x over texels [u0, u1), v along z over [v0, v1).
  const auto floor = [&](float x0, float x1, float z0, float z1, float u0, float u1, float v0, float v1) {
    quad({glm::vec3(x0, 0, z0), glm::vec3(x0, 0, z1), glm::vec3(x1, 0, z1), glm::vec3(x1, 0, z0)},
         {glm::vec2(u0, v0) / 32.0f, glm::vec2(u0, v1) / 32.0f, glm::vec2(u1, v1) / 32.0f, glm::vec2(u1, v0) / 32.0f}, grey);
  };
  floor(-1, 1, -1, 1, 1, 15, 1, 31);  // F: triangles 0, 1
  floor(5, 6, 0, 1, 17, 31, 1, 15);   // G: triangles 2, 3
  floor(8, 10, 0, 1, 17, 31, 17, 31);  // H: triangles 4, 5; x < 9 inside the box
  const glm::vec2 none(0.0f);
  quad({glm::vec3(-0.5f, 1, -0.5f), glm::vec3(0.5f, 1, -0.5f), glm::vec3(0.5f, 1, 0.5f), glm::vec3(-0.5f, 1, 0.5f)},
       {none, none, none, none}, lamp);  // facing down
  const std::size_t before_boxes = m.positions.size();
  m.add_box({4.8f, -0.2f, -0.2f}, {6.2f, 0.6f, 1.2f}, grey);
  m.add_box({7.8f, -0.2f, -0.2f}, {9.0f, 0.6f, 1.2f}, grey);
  m.lightmap_uvs.resize(m.positions.size(), none);
  REQUIRE(m.positions.size() > before_boxes);
  m.sky_radiance = glm::vec3(1.0f);
  bake_options o;
  o.width = o.height = 32;
  o.sampler.resolution = 16;
  const bake_input in = input_of(m);
  const bake_result r = bake_lightmap(in, o);
  const lightmap_samples smp = compute_lightmap_samples(in, 32, 32);
  float f_min = 1e30f, h_valid_max = 0.0f, h_invalid_max = 0.0f;
  std::size_t g = 0, g_invalid = 0, h_invalid = 0;
  for (std::size_t k = 0; k < smp.owner.size(); ++k) {
    if (!r.sampled[k]) continue;
    const float e = r.irradiance.pixels[3 * k + 1];
    if (smp.owner[k] < 2) f_min = std::min(f_min, e);
    if (smp.owner[k] == 2 || smp.owner[k] == 3) {
      ++g;
      g_invalid += r.valid[k] ? 0u : 1u;
      CHECK(e == 0.0f);  // no valid texel in its chart: nothing to fill it from (was F's light)
    }
    if (smp.owner[k] == 4 || smp.owner[k] == 5) {
      if (r.valid[k])
        h_valid_max = std::max(h_valid_max, e);
      else {
        ++h_invalid;
        h_invalid_max = std::max(h_invalid_max, e);
      }
    }
  }
  CHECK(g == 14u * 14u);
  CHECK(g_invalid == g);
  REQUIRE(h_invalid > 14u);
  INFO("F at least " << f_min << ", H's valid texels at most " << h_valid_max << ", its invalid ones " << h_invalid_max);
  CHECK(f_min > 2.0f * h_valid_max);  // F is much brighter than H
  CHECK(h_invalid_max > 0.0f);
  CHECK(h_invalid_max <= h_valid_max);  // H's invalid texels hold H's own light, not F's
}

TEST_CASE("Bakes are bitwise identical for 1 and 2 threads", "[bake]") {
  small_cornell c;
  const scene_mesh& m = c.mesh;
  bake_options o = c.options;
  o.thread_count = 1;
  const bake_result a = bake_lightmap(input_of(m), o);
  o.thread_count = 2;
  const bake_result b = bake_lightmap(input_of(m), o);
  REQUIRE(a.irradiance.pixels.size() == b.irradiance.pixels.size());
  CHECK(std::memcmp(a.irradiance.pixels.data(), b.irradiance.pixels.data(), a.irradiance.pixels.size() * sizeof(float)) == 0);
  CHECK(a.valid == b.valid);
  CHECK(a.stats.hemicubes == b.stats.hemicubes);
}

TEST_CASE("Cancelling from the progress callback throws cancelled in any pass", "[bake]") {
  small_cornell c;
  const scene_mesh& m = c.mesh;
  bake_options o = c.options;
  for (bool cache : {true, false})
    for (int stop_after : {0, 3}) {
      int calls = 0;
      float last = -1.0f;
      bool monotonic = true;
      o.use_cache = cache;
      o.progress = [&](float f) {
        if (f < last) monotonic = false;
        last = f;
        return calls++ < stop_after;
      };
      try {
        (void)bake_lightmap(input_of(m), o);
        FAIL("no exception");
      } catch (const error& e) {
        CHECK(e.code() == status::cancelled);
      }
      CHECK(calls == stop_after + 1);
      CHECK(monotonic);
    }
}

TEST_CASE("Reference mode renders a hemicube per sampled texel and agrees with the cache", "[bake]") {
  small_cornell c;
  scene_mesh m64 = cornell_box();  // 64 x 64: dense enough for the cache to interpolate
  generate_lightmap_uvs(m64, 64, 2);
  bake_options o = c.options;
  o.width = o.height = 64;
  o.bounces = 1;
  const bake_result cached = bake_lightmap(input_of(m64), o);
  o.use_cache = false;
  const bake_result ref = bake_lightmap(input_of(m64), o);
  CHECK(ref.stats.hemicubes == ref.stats.sampled_texels);
  CHECK(cached.stats.hemicubes < cached.stats.sampled_texels);
  double num = 0, den = 0;
  for (std::size_t k = 0; k < ref.sampled.size(); ++k)
    if (ref.sampled[k] && ref.valid[k] && cached.valid[k])
      for (std::size_t i = 3 * k; i < 3 * k + 3; ++i) {
        const double d = cached.irradiance.pixels[i] - ref.irradiance.pixels[i];
        num += d * d;
        den += double(ref.irradiance.pixels[i]) * ref.irradiance.pixels[i];
      }
  INFO("relative RMS difference " << std::sqrt(num / den));
  // a = 0.2 (default): the cache interpolates within about a per texel; the RMS over the map is
  // lower (measured 0.077 at N = 16, whose hemicubes are themselves noisy from texel to texel).
  CHECK(std::sqrt(num / den) < 0.1);
}

TEST_CASE("generate_lightmap_uvs packs non-overlapping charts at one texel density", "[bake]") {
  for (scene_mesh m : {cornell_box(), hexagon_room(1), sky_and_occluders()}) {
    const std::size_t tris = m.triangle_count();
    generate_lightmap_uvs(m, 128, 2);
    REQUIRE(m.lightmap_uvs.size() == m.positions.size());
    REQUIRE(m.triangle_count() == tris);
    const lightmap_samples s = compute_lightmap_samples(input_of(m), 128, 128);
    CHECK(s.overlapping_texels == 0);
    double lo = 1e30, hi = 0;
    for (std::size_t t = 0; t < tris; ++t) {
      const glm::vec3 p0 = m.positions[m.indices[3 * t]], p1 = m.positions[m.indices[3 * t + 1]], p2 = m.positions[m.indices[3 * t + 2]];
      const glm::vec2 u0 = m.lightmap_uvs[m.indices[3 * t]], u1 = m.lightmap_uvs[m.indices[3 * t + 1]], u2 = m.lightmap_uvs[m.indices[3 * t + 2]];
      const double a3 = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
      const double a2 = 0.5 * std::fabs(double((u1 - u0).x * (u2 - u0).y - (u1 - u0).y * (u2 - u0).x));
      if (a3 == 0.0) continue;
      lo = std::min(lo, a2 / a3);
      hi = std::max(hi, a2 / a3);
    }
    // One density for every chart: UV area / 3D area equal up to float rounding of the UVs.
    CHECK(hi / lo < 1.01);
  }
}

TEST_CASE("Bad input to the baker names the problem", "[bake]") {
  uv_mesh m;
  m.add({0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0}, {1, 0}, {0, 1});
  bake_options o;
  o.width = o.height = 8;
  o.sampler.resolution = 8;
  const auto throws_with = [&](const bake_input& in, const bake_options& opt, const std::string& part) {
    try {
      (void)bake_lightmap(in, opt);
      FAIL("no exception");
    } catch (const error& e) {
      CHECK(e.code() == status::invalid_argument);
      CHECK_THAT(e.what(), Catch::Contains(part));
    }
  };
  bake_options bad = o;
  bad.width = 0;
  throws_with(m.input(), bad, "lightmap size 0 x 8");
  bad.width = 1000000;
  throws_with(m.input(), bad, "lightmap size 1000000 x 8");
  bad = o;
  bad.bounces = 0;
  throws_with(m.input(), bad, "bounces 0");
  bad = o;
  bad.min_coverage = 2.0f;
  throws_with(m.input(), bad, "min_coverage");
  bake_input no_uv = m.input();
  no_uv.scene.lightmap_uvs = nullptr;
  throws_with(no_uv, o, "no lightmap UVs");
  uv_mesh outside = m;
  outside.uvs[1].x = 1.5f;
  throws_with(outside.input(), o, "lightmap_uvs[1].u = 1.5 is outside [0, 1] by more than lightmap_uv_tolerance");
  outside.uvs[1].x = 1.0f + 1.5f * lightmap_uv_tolerance;  // just past the tolerance
  throws_with(outside.input(), o, "lightmap_uvs[1].u = 1.0015");
  uv_mesh flat = m;
  flat.uvs[2] = flat.uvs[1];
  bake_options strict = o;
  strict.strict = true;
  throws_with(flat.input(), strict, "triangle 0 has zero area in lightmap UV space");
  // Without strict the triangle covers nothing, and nothing else does.
  throws_with(flat.input(), o, "no texel is covered by a triangle");
  uv_mesh far = m;
  far.indices[2] = 7;
  throws_with(far.input(), o, "indices[2] = 7 is out of range");
  std::vector<glm::vec3> normals(3, glm::vec3(std::nanf("")));
  bake_input nan_normals = m.input();
  nan_normals.normals = normals.data();
  throws_with(nan_normals, o, "normals[0] is not finite");
  // A degenerate 3D triangle with degenerate UVs is accepted (it covers nothing).
  uv_mesh degenerate = m;
  degenerate.add({0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0.5f, 0.5f}, {0.5f, 0.5f}, {0.5f, 0.5f});
  CHECK_NOTHROW(bake_lightmap(degenerate.input(), o));
}

// ---- directional lightmaps and the environment sky -------------------------------------------

namespace {

// The world directions of the HL2 basis in frame (t, b, n), written out from integrate.hpp's
// definition (not from bake.hpp's table).
std::array<glm::dvec3, 3> hl2_world(const glm::dvec3& t, const glm::dvec3& b, const glm::dvec3& n) {
  const double s6 = 1.0 / std::sqrt(6.0), s2 = 1.0 / std::sqrt(2.0), s3 = 1.0 / std::sqrt(3.0);
  return {-s6 * t + s2 * b + s3 * n, -s6 * t - s2 * b + s3 * n, std::sqrt(2.0 / 3.0) * t + s3 * n};
}

// Solid angle of a triangle seen from p (Van Oosterom & Strackee 1983).
double triangle_solid_angle(const glm::dvec3& p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  a -= p;
  b -= p;
  c -= p;
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double num = std::fabs(glm::dot(a, glm::cross(b, c)));
  const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

// A directional hemicube reference at N = 512 in the floors' texel frame (+z, +x, +y) of the
// directional tests below (integrate_options::directional: L1 SH and the HL2 basis).
struct floor_reference {
  explicit floor_reference(const scene_desc& d) : raster(scene::create(d)), integrator(512, directional()) {}
  irradiance_sample at(const glm::vec3& p) {
    raster.render(p, frame{{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, 512, buf);
    return integrator.integrate(buf);
  }
  static integrate_options directional() {
    integrate_options io;
    io.directional = true;
    return io;
  }
  hemicube_rasterizer raster;
  hemicube_integrator integrator;
  hemicube_buffer buf;
};

}  // namespace

TEST_CASE("Directional maps under a uniform sky match the closed forms in right- and left-handed charts", "[bake]") {
  // Two unoccluded quads under a uniform sky L = (1, 0.5, 2): a floor (normal +y) whose u runs
  // along +z and v along +x (tangent frame (+z, +x, +y), right-handed), and a quad tilted 45
  // degrees (normal (1, 1, 0)/sqrt 2) whose v runs along -z (a mirrored chart: left-handed).
  // Closed forms from integrate.hpp's definitions: c_00 = sqrt(pi) L, band 1 = (sqrt(3 pi)/2) L
  // (n_y, n_z, n_x); a plane tilted by beta under a uniform sky hemisphere receives
  // pi L (1 + cos beta) / 2, and every HL2 vector is at cos beta = 1/sqrt 3 from n.
  uv_mesh m;
  const glm::vec3 f0(0, 0, 0), f1(0, 0, 1), f2(1, 0, 1), f3(1, 0, 0);
  m.add(f0, f1, f2, {0, 0}, {0.5f, 0}, {0.5f, 1});
  m.add(f0, f2, f3, {0, 0}, {0.5f, 1}, {0, 1});
  // Tilted quad in the plane x + y = 3 (normal (1,1,0)/sqrt2), u along (-1, 1, 0)/sqrt2, v along
  // -z, below y = 0 so that neither quad sees the other.
  const glm::vec3 g0(13, -10, 1), g1(12, -9, 1), g2(12, -9, 0), g3(13, -10, 0);
  m.add(g0, g2, g1, {0.5f, 0}, {1, 1}, {1, 0});
  m.add(g0, g3, g2, {0.5f, 0}, {0.5f, 1}, {1, 1});
  bake_input in = m.input();
  in.scene.sky_radiance = glm::vec3(1.0f, 0.5f, 2.0f);
  const lightmap_samples smp = compute_lightmap_samples(in, 16, 8);
  const glm::vec3 tilt_n = glm::normalize(glm::vec3(1, 1, 0)), tilt_t = glm::normalize(glm::vec3(-1, 1, 0));
  for (std::size_t k = 0; k < smp.coverage.size(); ++k) {
    const bool floor = (k % 16) < 8;
    // The frames as built by hand from the UV layout above (float rounding of normalisation).
    CHECK(glm::length(smp.tangent[k] - (floor ? glm::vec3(0, 0, 1) : tilt_t)) < 1e-6f);
    CHECK(glm::length(smp.bitangent[k] - (floor ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, -1))) < 1e-6f);
    CHECK(glm::dot(glm::cross(smp.tangent[k], smp.bitangent[k]), smp.normal[k]) == Approx(floor ? 1.0 : -1.0).margin(1e-6));
  }
  for (bool cache : {true, false}) {
    bake_options o;
    o.width = 16;
    o.height = 8;
    o.sampler.resolution = 16;
    o.use_cache = cache;
    o.output_sh_l1 = o.output_hl2 = true;
    const bake_result r = bake_lightmap(in, o);
    REQUIRE(r.sh_l1[3].width == 16);
    REQUIRE(r.hl2[2].height == 8);
    const double k1 = std::sqrt(3.0 * pi) / 2.0;
    double worst = 0.0;
    for (std::size_t k = 0; k < 16 * 8; ++k) {
      const glm::dvec3 n = (k % 16) < 8 ? glm::dvec3(0, 1, 0) : glm::dvec3(tilt_n);
      for (int c = 0; c < 3; ++c) {
        const double l = in.scene.sky_radiance[c];
        const double sh[4] = {std::sqrt(pi) * l, k1 * l * n.y, k1 * l * n.z, k1 * l * n.x};
        for (int j = 0; j < 4; ++j) worst = std::max(worst, std::fabs(r.sh_l1[std::size_t(j)].pixels[3 * k + std::size_t(c)] - sh[j]) / l);
        for (int j = 0; j < 3; ++j)
          worst = std::max(worst, std::fabs(r.hl2[std::size_t(j)].pixels[3 * k + std::size_t(c)] - pi * l * (1 + 1 / std::sqrt(3.0)) / 2) / l);
      }
    }
    INFO("cache " << cache << ": worst deviation " << worst << " x L");
    // SH: exact texel weights summed in float/double (sums within 1e-6 of 2 pi and pi). HL2 (cone
    // series): the uniform sky's cone irradiance is constant, so the series is exact, but its
    // per-texel weights integrate the clamped cosine by the midpoint rule on 8 x 8 sub-rectangles
    // where the cone's horizon crosses a texel: measured 1.6e-5 L at N = 16. Bound 1e-4 L.
    CHECK(worst < 1e-4);
  }
}

TEST_CASE("Directional maps against Lambert's closed form and per-texel hemicubes in the texel frame", "[bake]") {
  // A 1 x 1 m floor (y = 0, u along +z on the left half of a 32 x 16 map, v along +x: tangent frame
  // (+z, +x, +y)) under a 0.4 x 0.4 m emitter (L = 2) facing down at 1.5 m, centred. From every
  // floor point the emitter lies within 33.5 degrees of the normal, so it is wholly above the
  // horizon of the normal and of every HL2 vector (54.7 degrees from n): closed forms, independent
  // of hemilight: band-1 SH = Y1 Phi (Phi = Lambert's vector irradiance), band 0 = Y00 L Omega
  // (Van Oosterom-Strackee solid angle), HL2_k = Phi . b_k.
  const double y00 = 0.28209479177387814, y1 = 0.4886025119029199, radiance = 2.0;
  uv_mesh m;
  const glm::vec3 f0(0, 0, 0), f1(0, 0, 1), f2(1, 0, 1), f3(1, 0, 0);
  m.add(f0, f1, f2, {0, 0}, {0.5f, 0}, {0.5f, 1});
  m.add(f0, f2, f3, {0, 0}, {0.5f, 1}, {0, 1});
  material lamp;
  lamp.emission = glm::vec3(float(radiance));
  lamp.albedo = glm::vec3(0.0f);
  const glm::vec3 e0(0.3f, 1.5f, 0.3f), e1(0.7f, 1.5f, 0.3f), e2(0.7f, 1.5f, 0.7f), e3(0.3f, 1.5f, 0.7f);
  m.add(e0, e1, e2, {0.55f, 0.1f}, {0.95f, 0.1f}, {0.95f, 0.5f}, lamp);  // (v1-v0) x (v2-v0) = -y: faces down
  m.add(e0, e2, e3, {0.55f, 0.1f}, {0.95f, 0.5f}, {0.55f, 0.5f}, lamp);
  const bake_input in = m.input();
  const std::vector<glm::dvec3> poly = {glm::dvec3(e0), glm::dvec3(e1), glm::dvec3(e2), glm::dvec3(e3)};
  const std::array<glm::dvec3, 3> basis = hl2_world({0, 0, 1}, {1, 0, 0}, {0, 1, 0});

  bake_options o;
  o.width = 32;
  o.height = 16;
  o.sampler.resolution = 64;
  o.output_sh_l1 = o.output_hl2 = true;
  o.cache.error_threshold = 0.1f;
  bake_options ref_o = o;
  ref_o.use_cache = false;
  const bake_result cached = bake_lightmap(in, o), per_texel = bake_lightmap(in, ref_o);

  // Per-texel reference in the texel's own frame: a hemicube rendered at the sample point with
  // the tangent frame (+z, +x, +y), integrated with integrate_options::directional, at N = 512 on
  // every fourth texel of every fourth row (at N = 64 without roll the emitter's edges line up
  // with the texel grid: 8 texel centres for 8.5 texels across, a 12% error at the centre).
  floor_reference reference(in.scene);

  double sh_err = 0, sh_norm = 0, trunc_err = 0, cache_err = 0, ref_err = 0, ref_norm = 0, hl2_norm = 0, worst_trunc = 0;
  for (int row = 0; row < 16; ++row)
    for (int col = 0; col < 16; ++col) {
      const std::size_t k = std::size_t(row * 32 + col);
      const glm::dvec3 p(double(row + 0.5) / 16.0, 0.0, double(col + 0.5) / 16.0);  // x = v, z = 2 u
      const glm::dvec3 phi = test::polygon_vector_irradiance(poly, p, radiance);
      const double omega = triangle_solid_angle(p, poly[0], poly[1], poly[2]) + triangle_solid_angle(p, poly[0], poly[2], poly[3]);
      const double sh[4] = {y00 * radiance * omega, y1 * phi.y, y1 * phi.z, y1 * phi.x};
      for (int j = 0; j < 4; ++j) {
        sh_err += std::pow(cached.sh_l1[std::size_t(j)].pixels[3 * k] - sh[j], 2.0);
        sh_norm += sh[j] * sh[j];
      }
      // HL2 from the exact L1 SH: the truncation error alone.
      std::array<glm::vec3, 4> exact_sh;
      for (std::size_t j = 0; j < 4; ++j) exact_sh[j] = glm::vec3(float(sh[j]));
      const std::array<glm::vec3, 3> from_exact = hl2_from_sh_l1(exact_sh, frame{{0, 0, 1}, {1, 0, 0}, {0, 1, 0}});
      const bool probe = row % 4 == 1 && col % 4 == 1;
      irradiance_sample ref;
      if (probe) {
        ref = reference.at(glm::vec3(p) + glm::vec3(0, 1e-4f, 0));
      }
      for (std::size_t j = 0; j < 3; ++j) {
        const double exact = glm::dot(phi, basis[j]);
        hl2_norm += exact * exact;
        trunc_err += std::pow(from_exact[j].x - exact, 2.0);
        cache_err += std::pow(cached.hl2[j].pixels[3 * k] - exact, 2.0);
        worst_trunc = std::max(worst_trunc, std::fabs(from_exact[j].x - exact) / phi.y);  // relative to E = n . Phi
        if (probe) {
          ref_err += std::pow(ref.hl2[j].x - exact, 2.0);
          ref_norm += exact * exact;
        }
      }
    }
  const double sh_rms = std::sqrt(sh_err / sh_norm), ref_rms = std::sqrt(ref_err / ref_norm),
               trunc_rms = std::sqrt(trunc_err / hl2_norm), cache_rms = std::sqrt(cache_err / hl2_norm);
  INFO("cached SH vs closed form: relative RMS " << sh_rms << "; HL2 relative RMS: N = 512 hemicube in the texel frame "
                                                  << ref_rms << ", from the exact L1 SH " << trunc_rms << " (worst " << worst_trunc
                                                  << " of E), baked (cone series, cache) " << cache_rms << "; records "
                                                  << cached.stats.records);
  // The N = 512 hemicube in the texel frame agrees with the closed form (texel-centre visibility
  // of the emitter's outline, 68 texels across: measured 0.8%): the frame convention of the
  // closed form is the integrator's.
  CHECK(ref_rms < 0.02);
  // Baked SH (N = 64, rolled hemicubes, a = 0.1): the emitter is 8.5 top-face texels across, so
  // texel-centre visibility misses or adds up to a texel row per edge; the per-texel roll turns
  // that into noise. Measured 2.1% RMS; 3% allowed.
  CHECK(sh_rms < 0.03);
  // HL2 through L1 SH (hl2_from_sh_l1 of the exact SH, deterministic): light from near the normal gives
  // L (1/4 + (1/2) cos 54.7) = 0.539 L instead of cos 54.7 = 0.577 L per unit source (-6.6%), and
  // off-centre texels see the source tilted towards some basis vectors and away from others.
  // Measured 13.2% RMS, worst 18.6% of E: the cost of the L1 representation (docs/bake.md), and
  // why the baker does not use it for HL2. Bounds 14% and 20%.
  CHECK(trunc_rms < 0.14);
  CHECK(worst_trunc < 0.20);
  // The baker does not go through L1 SH for HL2: it interpolates the records' cone series
  // (cache.hpp, hl2_cone), exact for light within 35.26 degrees of the normal as here, so the
  // baked HL2 keeps only the hemicube's discretisation error, as the SH above: measured 2.1%;
  // bound 3%.
  CHECK(cache_rms < 0.03);
}

TEST_CASE("Environment sky: an upward and a sideways quad match the cube map's cosine filter", "[bake]") {
  // Sky L(w) = 1 + 0.5 w_x + 0.3 w_y + 0.2 w_z + 0.4 w_x w_z (> 0) sampled at 64^2 texel centres.
  // Reference: filter_irradiance (cubemap.hpp) - the cosine-lobe quadrature over the map's own
  // texels, independent of the rasterizer - at its output texel whose centre is exactly +y (face
  // +Y) or +x (face +X) (odd output size 5: the central texel). The constant sky (100) must not
  // be seen. tests/test_cubemap.cpp measured hemicube (N = 64) vs filter ~1e-4; tolerance 1e-3.
  const int size = 64;
  cube_image env = cube_image::make(size, 3);
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::vec3 w = cubemap_texel_direction(size, f, x, y, edge_fixup::none);
        const float l = 1.0f + 0.5f * w.x + 0.3f * w.y + 0.2f * w.z + 0.4f * w.x * w.z;
        float* p = env.at(f, x, y);
        p[0] = l;
        p[1] = 0.5f * l;
        p[2] = 2.0f * l;
      }
  auto map = std::make_shared<const cubemap>(cubemap::from_image(env, false));
  const cube_image filtered = filter_irradiance(*map, 5);
  uv_mesh m;
  // Floor (normal +y) on the left half; on the right half a wall x = 5 facing +x, below y = 0:
  // neither sees the other.
  m.add({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {0, 0}, {0.5f, 0}, {0.5f, 1});
  m.add({0, 0, 0}, {1, 0, 1}, {1, 0, 0}, {0, 0}, {0.5f, 1}, {0, 1});
  m.add({5, -3, 0}, {5, -2, 0}, {5, -2, 1}, {0.5f, 0}, {1, 0}, {1, 1});
  m.add({5, -3, 0}, {5, -2, 1}, {5, -3, 1}, {0.5f, 0}, {1, 1}, {0.5f, 1});
  bake_input in = m.input();
  in.scene.sky_radiance = glm::vec3(100.0f);
  bake_options o;
  o.width = 16;
  o.height = 8;
  o.sampler.resolution = 64;
  o.sampler.raster.sky = map;
  o.output_sh_l1 = true;
  const bake_result r = bake_lightmap(in, o);
  const float* up = filtered.at(2, 2, 2);    // face +Y, centre: +y
  const float* side = filtered.at(0, 2, 2);  // face +X, centre: +x
  double worst = 0.0;
  for (std::size_t k = 0; k < 16 * 8; ++k) {
    const float* ref = (k % 16) < 8 ? up : side;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(r.irradiance.pixels[3 * k + std::size_t(c)] / ref[c] - 1.0));
  }
  INFO("worst relative difference to the cosine filter " << worst);
  CHECK(worst < 1e-3);
  // The SH band 0 sees the environment too: c_00 = Y00 x the integral of L over the upper
  // hemisphere, which for this L (the odd terms in x and z cancel over the +y hemisphere) is
  // 2 pi + 0.3 pi (integral of w_y) = 2.3 pi, times Y00; midpoint sampling of the map: 1e-3.
  CHECK(r.sh_l1[0].pixels[0] == Approx(0.28209479 * 2.3 * pi).epsilon(1e-3));
  // Bad maps are refused by name.
  o.sampler.raster.sky = std::make_shared<const cubemap>();
  test::require_error([&] { bake_lightmap(in, o); }, status::invalid_argument, "sampler: raster: the sky cube map");
}

TEST_CASE("write_bake_exrs writes the irradiance, mask and the requested directional maps", "[bake]") {
  small_cornell c;
  c.options.bounces = 1;
  c.options.output_hl2 = true;
  const bake_result r = bake_lightmap(input_of(c.mesh), c.options);
  CHECK(r.sh_l1[0].width == 0);  // not requested: empty
  const std::vector<std::string> files = write_bake_exrs(r, test::tmp_path("cornell_dir"));
  REQUIRE(files.size() == 5);
  CHECK(files[2] == test::tmp_path("cornell_dir") + "_hl2_0.exr");
  const image back = read_exr(files[3]);
  CHECK(back.pixels == r.hl2[1].pixels);  // float32 round-trips exactly
}

TEST_CASE("White furnace: directional maps of the full and the indirect-only bake match the uniform closed forms", "[bake]") {
  // In the closed uniform room (albedo a = 0.5, emission 1) pass k sees a uniform radiance
  // L = 1 + a + ... + a^(k-1) from every direction, so (integrate.hpp's definitions) the SH is
  // (sqrt(pi) L, (sqrt(3 pi)/2) L (n_y, n_z, n_x)) and every HL2 value pi L (1 + 1/sqrt3) / 2.
  // Indirect only: L - 1 (the first pass sees the emission L = 1). Float sums and the cone
  // weights' midpoint quadrature (previous tests): 1e-4 L.
  material m;
  m.albedo = glm::vec3(0.5f);
  m.emission = glm::vec3(1.0f);
  scene_mesh room = closed_room(m, m, 2);
  generate_lightmap_uvs(room, 32, 2);
  const lightmap_samples smp = compute_lightmap_samples(input_of(room), 32, 32);
  bake_options o;
  o.width = o.height = 32;
  o.sampler.resolution = 16;
  o.bounces = 3;
  o.output_sh_l1 = o.output_hl2 = true;
  for (bool indirect : {false, true}) {
    o.indirect_only = indirect;
    const bake_result r = bake_lightmap(input_of(room), o);
    const double l = indirect ? 0.75 : 1.75, k1 = std::sqrt(3.0 * pi) / 2.0;
    double worst = 0.0;
    for (std::size_t k = 0; k < r.sampled.size(); ++k) {
      if (!r.sampled[k]) continue;
      const glm::dvec3 n(smp.normal[k]);
      const double sh[4] = {std::sqrt(pi) * l, k1 * l * n.y, k1 * l * n.z, k1 * l * n.x};
      for (int j = 0; j < 4; ++j) worst = std::max(worst, std::fabs(r.sh_l1[std::size_t(j)].pixels[3 * k + 1] - sh[j]));
      for (int j = 0; j < 3; ++j)
        worst = std::max(worst, std::fabs(r.hl2[std::size_t(j)].pixels[3 * k + 1] - pi * l * (1 + 1 / std::sqrt(3.0)) / 2));
    }
    INFO((indirect ? "indirect only" : "full") << ": worst deviation " << worst << " for L = " << l);
    CHECK(worst < 1e-4 * l);
  }
}

TEST_CASE("HL2 maps of a grazing side light in right- and left-handed charts against hemicubes in the texel frame", "[bake]") {
  // Two 1 x 1 m floors, each lit by its own 0.6 x 0.8 m wall emitter (L = 2) standing 0.4 m beyond
  // its edge, so light arrives 20-80 degrees from the normal: well outside the 35.26-degree cone
  // where the HL2 cone series is exact, and strongly directional. Floor A's chart is right-handed
  // (t = +z, b = +x), floor B's mirrored (t = +z, b = -x). Reference, independent of the cache and
  // of the cone series: at every third texel a hemicube rendered at N = 512 in the texel's frame
  // and integrated with integrate_options::directional (for B, rendered in the right-handed frame
  // (t, -b, n), where HL2 vectors 0 and 1 trade places).
  uv_mesh m;
  material lamp;
  lamp.emission = glm::vec3(2.0f);
  lamp.albedo = glm::vec3(0.0f);
  m.add({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {0, 0}, {0.25f, 0}, {0.25f, 1});
  m.add({0, 0, 0}, {1, 0, 1}, {1, 0, 0}, {0, 0}, {0.25f, 1}, {0, 1});
  m.add({1, 0, 10}, {0, 0, 11}, {1, 0, 11}, {0.25f, 0}, {0.5f, 1}, {0.5f, 0});
  m.add({1, 0, 10}, {0, 0, 10}, {0, 0, 11}, {0.25f, 0}, {0.25f, 1}, {0.5f, 1});
  for (float z0 : {0.0f, 10.0f}) {  // wall emitters at x = 1.4 facing -x
    const float u0 = z0 == 0.0f ? 0.5f : 0.75f;
    m.add({1.4f, 0.1f, z0 + 0.2f}, {1.4f, 0.1f, z0 + 0.8f}, {1.4f, 0.9f, z0 + 0.8f}, {u0, 0}, {u0 + 0.2f, 0}, {u0 + 0.2f, 0.5f}, lamp);
    m.add({1.4f, 0.1f, z0 + 0.2f}, {1.4f, 0.9f, z0 + 0.8f}, {1.4f, 0.9f, z0 + 0.2f}, {u0, 0}, {u0 + 0.2f, 0.5f}, {u0, 0.5f}, lamp);
  }
  const bake_input in = m.input();
  bake_options o;
  o.width = 64;
  o.height = 16;
  o.sampler.resolution = 64;
  o.cache.error_threshold = 0.1f;
  o.output_sh_l1 = o.output_hl2 = true;
  const bake_result r = bake_lightmap(in, o);
  const lightmap_samples smp = compute_lightmap_samples(in, 64, 16);

  floor_reference reference(in.scene);
  double cone_err = 0, sh_err = 0, norm = 0;
  for (int floor_b = 0; floor_b < 2; ++floor_b)
    for (int row = 1; row < 16; row += 3)
      for (int col = 1; col < 16; col += 3) {
        const std::size_t k = std::size_t(row * 64 + col + 16 * floor_b);
        const double v = (row + 0.5) / 16.0, z = (col + 0.5) / 16.0;
        const glm::vec3 p = floor_b ? glm::vec3(float(1.0 - v), 1e-4f, float(10.0 + z)) : glm::vec3(float(v), 1e-4f, float(z));
        // The texel frames as laid out above (not read from the baker).
        const glm::vec3 b = floor_b ? glm::vec3(-1, 0, 0) : glm::vec3(1, 0, 0);
        CHECK(glm::length(smp.bitangent[k] - b) < 1e-6f);
        const irradiance_sample ref = reference.at(p);
        std::array<glm::vec3, 4> sh;
        for (std::size_t j = 0; j < 4; ++j) {
          const float* q = &r.sh_l1[j].pixels[3 * k];
          sh[j] = glm::vec3(q[0], q[1], q[2]);
        }
        const std::array<glm::vec3, 3> via_sh = hl2_from_sh_l1(sh, frame{{0, 0, 1}, b, {0, 1, 0}});
        for (std::size_t j = 0; j < 3; ++j) {
          const std::size_t rj = floor_b && j < 2 ? 1 - j : j;  // mirrored chart: basis 0 <-> 1
          const double want = ref.hl2[rj].x;
          norm += want * want;
          cone_err += std::pow(r.hl2[j].pixels[3 * k] - want, 2.0);
          sh_err += std::pow(via_sh[j].x - want, 2.0);
        }
      }
  const double cone_rms = std::sqrt(cone_err / norm), sh_rms = std::sqrt(sh_err / norm);
  INFO("HL2 relative RMS against N = 512 hemicubes in the texel frame: baked (cone series) " << cone_rms
                                                                                           << ", from the baked L1 SH " << sh_rms);
  // Baked HL2 (N = 64 hemicubes, cache a = 0.1, cone series of order 3): the order-3 cut of the
  // clamped cosine plus the N = 64 texel-centre error of the 0.6 x 0.8 m emitter. Measured 1.7%;
  // 3% allowed. Through L1 SH instead the same maps would be off by the measured 25%, which is
  // why the baker uses the cone series.
  CHECK(cone_rms < 0.03);
  CHECK(sh_rms > 3 * cone_rms);
}

namespace {

// A thin post standing on a floor slab under a uniform sky (radiance 1), as on real open-air
// assets: closed parts that meet. Slab 2 x 2 x 0.1 m (top y = 0, albedo 0.5), post 0.2 x 0.2 m
// (x, z in [-0.1, 0.1]) from y = -0.02 (2 cm into the slab: its bottom cap lies inside) to 1.5 m.
// Floor texels under the post are inside geometry; the ones around it hold the contact shadow.
struct post_on_slab {
  scene_mesh mesh;
  bake_options options;
  post_on_slab() {
    mesh.add_box({-1.0f, -0.1f, -1.0f}, {1.0f, 0.0f, 1.0f}, {glm::vec3(0.0f), glm::vec3(0.5f), false});
    mesh.add_box({-0.1f, -0.02f, -0.1f}, {0.1f, 1.5f, 0.1f}, {glm::vec3(0.0f), glm::vec3(0.7f), false});
    mesh.sky_radiance = glm::vec3(1.0f);
    generate_lightmap_uvs(mesh, 256, 2);
    options.width = options.height = 256;
    options.sampler.resolution = 64;
    options.bounces = 1;
  }
  // Distance in x-z from the post's footprint (0 on it).
  static float distance_to_post(const glm::vec3& p) {
    const float dx = std::max(std::fabs(p.x) - 0.1f, 0.0f), dz = std::max(std::fabs(p.z) - 0.1f, 0.0f);
    return std::sqrt(dx * dx + dz * dz);
  }
};

}  // namespace

TEST_CASE("A post on a slab under the sky keeps its contact shadow: floor texels by the post stay valid and dark", "[bake]") {
  const post_on_slab s;
  const bake_input in = input_of(s.mesh);
  const bake_result r = bake_lightmap(in, s.options);
  const lightmap_samples smp = compute_lightmap_samples(in, s.options.width, s.options.height);
  // Reference: a hemicube at N = 256 at each floor-top sample within 0.4 m of the post (the
  // bake's own sample points: bake.hpp, step 2), the mean of two rolls. N = 256 against the
  // bake's N = 64: the reference's own aliasing is ~4x smaller.
  const auto sc = scene::create(in.scene);
  const float min_offset = 2.0f * default_near_distance(*sc);
  sampler_options so;
  so.resolution = 256;
  const irradiance_sampler reference = make_hemicube_sampler(sc, so, 1);
  const float bins[] = {0.0f, 0.05f, 0.1f, 0.2f, 0.4f};
  double sum_bake[4] = {}, sum_ref[4] = {}, num = 0.0, den = 0.0;
  std::size_t count[4] = {}, outside = 0, outside_invalid = 0, under_post = 0, under_post_invalid = 0;
  for (std::size_t k = 0; k < smp.coverage.size(); ++k) {
    if (!r.sampled[k] || smp.normal[k].y < 0.99f || std::fabs(smp.position[k].y) > 1e-5f) continue;  // floor top only
    const float d = post_on_slab::distance_to_post(smp.position[k]);
    const float texel = smp.texel_world_size[k];
    if (d == 0.0f && std::fabs(smp.position[k].x) < 0.1f - texel && std::fabs(smp.position[k].z) < 0.1f - texel) {
      ++under_post;
      under_post_invalid += r.valid[k] ? 0u : 1u;
    }
    if (d <= texel || d > bins[4]) continue;  // texels the post's wall does not cut
    ++outside;
    outside_invalid += r.valid[k] ? 0u : 1u;
    const glm::vec3 p = smp.position[k] + std::max(min_offset, s.options.offset_texels * texel) * smp.normal[k];
    glm::vec3 q = p;
    q.x = std::nextafter(q.x, 1e30f);  // one float ulp: another hashed roll, the same point
    const double e_ref = 0.5 * (double(reference(0, p, smp.normal[k]).irradiance.y) + reference(0, q, smp.normal[k]).irradiance.y);
    const double e = r.irradiance.pixels[3 * k + 1];
    num += (e - e_ref) * (e - e_ref);
    den += e_ref * e_ref;
    for (int b = 0; b < 4; ++b)
      if (d > bins[b] && d <= bins[b + 1]) {
        sum_bake[b] += e;
        sum_ref[b] += e_ref;
        ++count[b];
      }
  }
  REQUIRE(outside > 100);
  REQUIRE(under_post > 10);
  // Invalidity stays where the samples themselves are inside geometry: every floor texel outside
  // the post is valid, every one well inside its footprint invalid.
  CHECK(outside_invalid == 0);
  CHECK(under_post_invalid == under_post);
  const double rms = std::sqrt(num / den);
  INFO("contact region: " << outside << " texels, relative RMS " << rms);
  for (int b = 0; b < 4; ++b) {
    const double mb = sum_bake[b] / double(count[b]), mr = sum_ref[b] / double(count[b]);
    INFO("ring " << bins[b] << "-" << bins[b + 1] << " m: " << count[b] << " texels, bake " << mb << ", N = 256 " << mr);
    REQUIRE(count[b] > 10);
    // The contact shadow survives: each ring's mean within 2% of the reference.
    CHECK(std::fabs(mb / mr - 1.0) < 0.02);
  }
  // ... and it is a shadow: the ring at the post is darker than 0.4 m away (the post hides a
  // quarter of the sky there: measured ~0.74 of the outer ring's value).
  CHECK(sum_ref[0] / double(count[0]) < 0.9 * sum_ref[3] / double(count[3]));
  // Per texel: the bake's N = 64 hemicubes alias by ~1-2% per texel; 3% bounds that plus interpolation.
  CHECK(rms < 0.03);
}

// ---- lights (bake_options::lights) ------------------------------------------------------------

namespace {

// A unit floor (y = 0, normal +y, u along +z over [0, 0.75], v along +x) and, when `occluder`,
// a black square [0.4, 0.6]^2 at height 0.3 facing down (so the floor sees its front face and
// is not taken for inside geometry), charted at u in [0.8, 1], v in [0, 0.2].
uv_mesh lit_floor(bool occluder) {
  uv_mesh m;
  const glm::vec3 f0(0, 0, 0), f1(0, 0, 1), f2(1, 0, 1), f3(1, 0, 0);
  m.add(f0, f1, f2, {0, 0}, {0.75f, 0}, {0.75f, 1});
  m.add(f0, f2, f3, {0, 0}, {0.75f, 1}, {0, 1});
  if (occluder) {
    const glm::vec3 o0(0.4f, 0.3f, 0.4f), o1(0.4f, 0.3f, 0.6f), o2(0.6f, 0.3f, 0.6f), o3(0.6f, 0.3f, 0.4f);
    m.add(o0, o2, o1, {0.8f, 0}, {1, 0.2f}, {1, 0});
    m.add(o0, o3, o2, {0.8f, 0}, {0.8f, 0.2f}, {1, 0.2f});
  }
  return m;
}

// The floor point under texel (x, y) of a size x size lightmap of lit_floor (texel centre).
glm::dvec3 floor_point(int x, int y, int size) {
  const double u = (x + 0.5) / size, v = (y + 0.5) / size;
  return {v, 0.0, u / 0.75};
}

light hard_sun(const glm::vec3& travel, float e) {
  light l;
  l.type = light_type::directional;
  l.direction = travel;
  l.color = glm::vec3(e);
  l.radius = 0.0f;
  return l;
}

}  // namespace

TEST_CASE("Bake with a hard sun: the floor gets E cos theta, the SH and HL2 maps the sun's direction", "[bake][lights]") {
  const uv_mesh m = lit_floor(false);
  const glm::vec3 travel = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
  const float e_sun = 2.0f;
  const int size = 16;
  bake_options o;
  o.width = o.height = size;
  o.sampler.resolution = 16;
  o.lights = {hard_sun(travel, e_sun)};
  o.output_sh_l1 = o.output_hl2 = true;
  const bake_result r = bake_lightmap(m.input(), o);
  CHECK(r.stats.direct_seconds > 0.0);
  const glm::dvec3 w = -glm::dvec3(travel);  // towards the sun
  const double e = e_sun * w.y;              // E cos theta on the floor (sky 0, nothing else)
  double worst_e = 0.0, worst_dir = 0.0;
  std::size_t floor_texels = 0;
  // The floor's lightmap frame from its UV layout: t = +z (u), b = +x (v), n = +y.
  const glm::dvec3 t(0, 0, 1), b(1, 0, 0), n(0, 1, 0);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size * 3 / 4; ++x) {
      const std::size_t k = std::size_t(y) * size + std::size_t(x);
      if (!r.sampled[k]) continue;
      ++floor_texels;
      worst_e = std::max(worst_e, std::fabs(r.irradiance.pixels[3 * k] - e) / e);
      // Radiance e_sun from direction w (as a delta): c = e_sun Y(w); HL2 = e_sun max(0, b_k . w).
      const double sh[4] = {0.282094792 * e_sun, 0.488602512 * w.y * e_sun, 0.488602512 * w.z * e_sun,
                            0.488602512 * w.x * e_sun};
      for (std::size_t j = 0; j < 4; ++j) worst_dir = std::max(worst_dir, std::fabs(r.sh_l1[j].pixels[3 * k] - sh[j]) / e_sun);
      for (std::size_t j = 0; j < 3; ++j) {
        const glm::dvec3 bk = t * double(hl2_basis[j][0]) + b * double(hl2_basis[j][1]) + n * double(hl2_basis[j][2]);
        worst_dir = std::max(worst_dir, std::fabs(r.hl2[j].pixels[3 * k] - e_sun * std::max(0.0, glm::dot(bk, w))) / e_sun);
      }
    }
  REQUIRE(floor_texels > 150);
  INFO("worst relative E error " << worst_e << ", worst SH/HL2 error " << worst_dir << " x E_sun");
  // A hard sun unoccluded is the closed form in float (one cos, one multiply): 1e-5. The
  // directional terms divide by cos and multiply back: 1e-5 of E_sun.
  CHECK(worst_e < 1e-5);
  CHECK(worst_dir < 1e-5);
}

TEST_CASE("Bake with a hard sun: a square occluder's umbra is exactly 0, the rest exactly lit, in the map and the shadow mask", "[bake][lights]") {
  const uv_mesh m = lit_floor(true);
  const int size = 64;
  bake_options o;
  o.width = o.height = size;
  o.sampler.resolution = 16;
  o.lights = {hard_sun({0.0f, -1.0f, 0.0f}, 3.0f)};
  o.shadow_mask_lights = {{0, -1, -1, -1}};
  const bake_result r = bake_lightmap(m.input(), o);
  REQUIRE(r.shadow_mask.channels == 4);
  REQUIRE(r.shadow_mask.width == size);
  std::size_t umbra = 0, lit = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size * 3 / 4 - 1; ++x) {
      const std::size_t k = std::size_t(y) * size + std::size_t(x);
      if (!r.sampled[k]) continue;
      const glm::dvec3 p = floor_point(x, y, size);
      // A texel's sample lies within the texel; a texel is 1/64 wide in x and 1/48 in z.
      const double margin = 0.03;
      const bool inside = p.x > 0.4 + margin && p.x < 0.6 - margin && p.z > 0.4 + margin && p.z < 0.6 - margin;
      const bool outside = p.x < 0.4 - margin || p.x > 0.6 + margin || p.z < 0.4 - margin || p.z > 0.6 + margin;
      if (inside) {
        ++umbra;
        CHECK(r.irradiance.pixels[3 * k] == 0.0f);
        CHECK(r.shadow_mask.pixels[4 * k] == 0.0f);
      } else if (outside) {
        ++lit;
        CHECK(r.irradiance.pixels[3 * k] == Approx(3.0).epsilon(1e-6));
        CHECK(r.shadow_mask.pixels[4 * k] == 1.0f);
      }
      CHECK(r.shadow_mask.pixels[4 * k + 1] == 0.0f);  // unused channels
      CHECK(r.shadow_mask.pixels[4 * k + 3] == 0.0f);
    }
  CHECK(umbra > 40);
  CHECK(lit > 1500);
  // casts_shadows = false: the occluder is ignored.
  o.lights[0].casts_shadows = false;
  const bake_result u = bake_lightmap(m.input(), o);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size * 3 / 4 - 1; ++x) {
      const std::size_t k = std::size_t(y) * size + std::size_t(x);
      if (u.sampled[k]) CHECK(u.irradiance.pixels[3 * k] == Approx(3.0).epsilon(1e-6));
    }
}

TEST_CASE("White furnace lit by a point light: the mean irradiance follows the geometric series, indirect-only drops the light", "[bake][lights]") {
  // A closed unit room of albedo a with a point light of intensity I at its centre: all of the
  // light's power 4 pi I lands on the walls (area 6), and each bounce returns a of what lands, so
  // the area mean of E after `bounces` passes is (4 pi I / 6) (1 + a + ... + a^(bounces-1)) for
  // any enclosure. generate_lightmap_uvs packs the six faces at one texel density, so the mean
  // over sampled texels is the area mean up to the texel grid's quadrature.
  const float a = 0.5f, intensity = 2.0f;
  material m;
  m.albedo = glm::vec3(a);
  scene_mesh room = closed_room(m, m, 4);
  generate_lightmap_uvs(room, 64, 2);
  light l;
  l.type = light_type::point;
  l.position = glm::vec3(0.5f);
  l.color = glm::vec3(intensity);
  bake_options o;
  o.width = o.height = 64;
  o.sampler.resolution = 32;
  o.thread_count = 2;
  o.lights = {l};
  const double direct_mean = 4.0 * pi * intensity / 6.0;
  for (int bounces = 1; bounces <= 3; ++bounces) {
    o.bounces = bounces;
    double series = 0.0;
    for (int j = 0; j < bounces; ++j) series += std::pow(double(a), j);
    for (bool indirect : {false, true}) {
      if (indirect && bounces == 1) continue;
      o.indirect_only = indirect;
      const bake_result r = bake_lightmap(input_of(room), o);
      double sum = 0.0;
      std::size_t n = 0;
      for (std::size_t k = 0; k < r.sampled.size(); ++k)
        if (r.sampled[k]) {
          sum += r.irradiance.pixels[3 * k];
          ++n;
        }
      const double mean = sum / double(n), expected = direct_mean * (indirect ? series - 1.0 : series);
      INFO("bounces " << bounces << (indirect ? " indirect only" : " full") << ": mean E " << mean << ", closed form " << expected);
      // The direct part is the texel grid's midpoint rule over I cos / d^2 (with the samples'
      // offset from the walls): measured +0.7%. The bounces carry it (indirect / direct =
      // 0.502 for a = 0.5) with the hemicube's (N = 32) and the radiance texture's
      // discretisation: measured +0.9% (full) and +1.1% (indirect only) at 3 bounces. Bound 2%.
      CHECK(mean == Approx(expected).epsilon(0.02));
    }
  }
}

TEST_CASE("Bakes with lights are bitwise identical for 1 and 2 threads", "[bake][lights]") {
  small_cornell c;
  bake_options o = c.options;
  light sphere;
  sphere.type = light_type::point;
  sphere.position = glm::vec3(0.3f, 0.8f, 0.4f);  // inside the box, off-centre
  sphere.radius = 0.05f;
  sphere.color = glm::vec3(1.0f, 0.8f, 0.6f);
  light rect;
  rect.type = light_type::rect;
  rect.position = glm::vec3(0.5f, 0.99f, 0.5f);
  rect.direction = glm::vec3(0, -1, 0);
  rect.width = rect.height = 0.2f;
  o.lights = {sphere, rect};
  o.output_sh_l1 = true;
  o.shadow_mask_lights = {{1, 0, -1, -1}};
  o.thread_count = 1;
  const bake_result a = bake_lightmap(input_of(c.mesh), o);
  o.thread_count = 2;
  const bake_result b = bake_lightmap(input_of(c.mesh), o);
  CHECK(std::memcmp(a.irradiance.pixels.data(), b.irradiance.pixels.data(), a.irradiance.pixels.size() * sizeof(float)) == 0);
  CHECK(std::memcmp(a.sh_l1[1].pixels.data(), b.sh_l1[1].pixels.data(), a.sh_l1[1].pixels.size() * sizeof(float)) == 0);
  CHECK(a.shadow_mask.pixels == b.shadow_mask.pixels);
}

TEST_CASE("Bad lights and shadow-mask indices fail the bake naming the light and field", "[bake][lights]") {
  small_cornell c;
  bake_options o = c.options;
  light l;
  l.type = light_type::point;
  l.radius = -1.0f;
  o.lights = {light{}, l};
  CHECK_THROWS_WITH(bake_lightmap(input_of(c.mesh), o), Catch::Contains("bake_lightmap: lights[1].radius"));
  o.lights = {light{}};
  o.shadow_mask_lights = {{0, 1, -1, -1}};
  CHECK_THROWS_WITH(bake_lightmap(input_of(c.mesh), o), Catch::Contains("shadow_mask_lights[1] = 1"));
  o.shadow_mask_lights = {{-1, -1, -1, -1}};
  o.direct.penumbra_samples = 2;
  CHECK_THROWS_WITH(bake_lightmap(input_of(c.mesh), o), Catch::Contains("bake_lightmap: direct_options: penumbra_samples"));
}

// ---- input as real exports give it: degenerate triangles, broken UVs, UVs a hair outside -------

namespace {

// A unit floor (local x, z in [0, 1], facing up) of 4 x 4 quads, exported the way levels come:
// every triangle with its own three vertices (duplicates at shared corners), the whole thing moved
// by a node transform applied in double and rounded to float. UVs: u = x, v = z / 2 (the lower
// half of the map), except that vertices at x = 0 have u = -0.00048 (a packer's margin). Options:
//   occluder     a 0.4 x 0.4 quad at height 0.3 facing down, with UVs in the upper half of the
//                map, or (broken_occluder) all at one point: 3D area but no UV area;
//   degenerate   collinear slivers along the floor's edges (midpoints exact in the local frame,
//                collinear only up to the transform's rounding) with UV triangles of real area
//                in the map's free upper corner, a triangle with a zero-length edge (two
//                duplicate vertices) and one collapsed to a point.
struct exported_floor {
  uv_mesh mesh;
  std::size_t occluder_first = 0, degenerate = 0, clamped = 0;
  std::size_t nonzero_area = 0;  // degenerate triangles whose area in double is not 0 (collinear only up to rounding)

  static glm::vec3 place(const glm::dvec3& local) {  // rotation about y by 0.6 rad, then a translation
    const double c = std::cos(0.6), s = std::sin(0.6);
    return glm::vec3(glm::dvec3(c * local.x + s * local.z, local.y, -s * local.x + c * local.z) + glm::dvec3(37.25, 2.5, -11.75));
  }
  void add(const glm::dvec3 (&p)[3], const glm::vec2 (&uv)[3], const material& m) {
    mesh.add(place(p[0]), place(p[1]), place(p[2]), uv[0], uv[1], uv[2], m);
  }

  exported_floor(bool occluder, bool broken_occluder, bool degenerate_triangles) {
    material grey;
    grey.albedo = glm::vec3(0.5f);
    const auto floor_uv = [&](const glm::dvec3& p) {
      if (p.x == 0.0) ++clamped;
      return glm::vec2(p.x == 0.0 ? -0.00048f : float(p.x), float(p.z / 2.0));
    };
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const glm::dvec3 a(i / 4.0, 0, j / 4.0), b((i + 1) / 4.0, 0, j / 4.0), c((i + 1) / 4.0, 0, (j + 1) / 4.0),
            d(i / 4.0, 0, (j + 1) / 4.0);
        add({a, d, c}, {floor_uv(a), floor_uv(d), floor_uv(c)}, grey);  // counter-clockwise seen from +y
        add({a, c, b}, {floor_uv(a), floor_uv(c), floor_uv(b)}, grey);
      }
    if (degenerate_triangles) {
      const glm::vec2 free_uv[3] = {{0.8f, 0.8f}, {0.95f, 0.8f}, {0.95f, 0.95f}};  // real UV area, unused by anything
      for (int k = 0; k < 4; ++k) {
        const double x0 = k / 4.0, x1 = (k + 1) / 4.0;
        add({glm::dvec3(x0, 0, 0), glm::dvec3(0.5 * (x0 + x1), 0, 0), glm::dvec3(x1, 0, 0)}, free_uv, grey);
        add({glm::dvec3(0, 0, x1), glm::dvec3(0, 0, 0.5 * (x0 + x1)), glm::dvec3(0, 0, x0)}, free_uv, grey);
        degenerate += 2;
      }
      for (std::size_t t = mesh.indices.size() / 3 - 8; t < mesh.indices.size() / 3; ++t) {
        const glm::dvec3 a(mesh.positions[3 * t]), b(mesh.positions[3 * t + 1]), c(mesh.positions[3 * t + 2]);
        if (glm::length(glm::cross(b - a, c - a)) > 0.0) ++nonzero_area;
      }
      const glm::dvec3 p(0.5, 0, 0.5), q(0.75, 0, 0.5);
      add({p, p, q}, free_uv, grey);  // a zero-length edge: vertices 0 and 1 are duplicates
      add({q, q, q}, free_uv, grey);
      degenerate += 2;
    }
    if (occluder) {
      occluder_first = mesh.indices.size() / 3;
      const glm::dvec3 a(0.3, 0.3, 0.3), b(0.7, 0.3, 0.3), c(0.7, 0.3, 0.7), d(0.3, 0.3, 0.7);
      const glm::vec2 ua(0.1f, 0.55f), ub(0.4f, 0.55f), uc(0.4f, 0.7f), ud(0.1f, 0.7f);
      const glm::vec2 point(0.25f, 0.6f);
      if (broken_occluder) {
        add({a, b, c}, {point, point, point}, grey);  // counter-clockwise seen from below
        add({a, c, d}, {point, point, point}, grey);
      } else {
        add({a, b, c}, {ua, ub, uc}, grey);
        add({a, c, d}, {ua, uc, ud}, grey);
      }
    }
  }
};

// The texels of the floor (the lower half of a size x size map): their irradiance, bit for bit.
std::vector<float> floor_texels(const bake_result& r, int size) {
  return std::vector<float>(r.irradiance.pixels.begin(), r.irradiance.pixels.begin() + std::ptrdiff_t(3 * size * size / 2));
}

}  // namespace

TEST_CASE("Bake: degenerate triangles are skipped, UVs a hair outside clamped, UV-less triangles occlude and are named", "[bake]") {
  constexpr int size = 16;
  bake_options o;
  o.width = o.height = size;
  o.sampler.resolution = 16;
  o.use_cache = false;  // a hemicube per texel: a texel's value depends only on its sample and the scene drawn
  o.thread_count = 2;
  const exported_floor clean(true, false, false), messy(true, true, true), open(false, false, false);
  const auto under_sky = [](const exported_floor& f) {
    bake_input in = f.mesh.input();
    in.scene.sky_radiance = glm::vec3(1.0f);
    return in;
  };
  const bake_result ref = bake_lightmap(under_sky(clean), o);
  const bake_result r = bake_lightmap(under_sky(messy), o);
  // The counts and the warnings name what was skipped.
  CHECK(r.stats.degenerate_triangles == messy.degenerate);
  CHECK(r.stats.degenerate_triangles == 10);
  CHECK(messy.nonzero_area > 0);  // slivers that an exact zero-area test would have drawn
  CHECK(r.stats.no_uv_area_triangles == 2);
  CHECK(r.stats.first_no_uv_area_triangle == messy.occluder_first);
  CHECK(r.stats.clamped_uvs == messy.clamped);
  CHECK(messy.clamped == 12);  // the vertices at x = 0 of the four leftmost quads' triangles (2 + 1 each)
  REQUIRE(r.stats.warnings.size() == 2);
  CHECK_THAT(r.stats.warnings[0], Catch::Contains("bake_lightmap: 12 lightmap UVs lie outside [0, 1] by up to 0.00047999"));
  CHECK_THAT(r.stats.warnings[1], Catch::Contains("bake_lightmap: 2 triangles have 3D area but no lightmap UV area (the first: triangle " +
                                                  std::to_string(messy.occluder_first) + "): they occlude but get no texels"));
  CHECK(ref.stats.warnings.size() == 1);  // the clamped UVs only
  // The floor's texels are bitwise those of the clean export (UVs clamped to exactly 0, the
  // occluder drawn, the degenerate triangles neither drawn nor covering texels) ...
  CHECK(floor_texels(r, size) == floor_texels(ref, size));
  // ... and the occluder really occludes: under it the floor gets well below the open sky's pi.
  const bake_result lit = bake_lightmap(under_sky(open), o);
  const std::size_t under = std::size_t(4 * size + size / 2);  // texel (8, 4): uv (0.53, 0.28), so x = 0.53, z = 0.56
  // The open floor sees the sky alone: pi (the projected solid angles sum to pi; float rounding).
  CHECK(lit.irradiance.pixels[3 * under] == Approx(pi).epsilon(1e-5));
  CHECK(r.irradiance.pixels[3 * under] < 0.9f * lit.irradiance.pixels[3 * under]);
  // Nothing but the floor and the well-formed occluder covers texels: the degenerate slivers' UV
  // triangle (upper right) and the broken occluder's point stay empty.
  for (int y = size / 2; y < size; ++y)
    for (int x = 0; x < size; ++x) CHECK(r.coverage[std::size_t(y * size + x)] == 0.0f);
  // strict: the UV-less triangles are an error naming the first; the rest is still accepted.
  bake_options strict = o;
  strict.strict = true;
  test::require_error([&] { bake_lightmap(under_sky(messy), strict); }, status::invalid_argument,
                      "bake_lightmap: triangle " + std::to_string(messy.occluder_first) + " has zero area in lightmap UV space");
  const exported_floor strict_ok(true, false, true);
  CHECK(bake_lightmap(under_sky(strict_ok), strict).stats.degenerate_triangles == 10);
  // bake_scene, the same rules: one page holding the floor and the occluder as two meshes gives
  // bitwise the same lightmap and counts, and its warnings name the mesh.
  scene_bake_input si;
  si.geometry = under_sky(messy);
  si.pages.resize(1);
  si.pages[0].width = si.pages[0].height = size;
  si.meshes.resize(2);
  si.meshes[0].triangle_count = messy.occluder_first;
  si.meshes[0].page = 0;
  si.meshes[1].first_triangle = messy.occluder_first;
  si.meshes[1].triangle_count = 2;
  si.meshes[1].page = 0;
  const scene_bake_result sr = bake_scene(si, o);
  CHECK(sr.pages[0].irradiance.pixels == r.irradiance.pixels);
  CHECK(sr.stats.degenerate_triangles == 10);
  CHECK(sr.stats.no_uv_area_triangles == 2);
  CHECK(sr.stats.first_no_uv_area_triangle == messy.occluder_first);
  CHECK(sr.stats.clamped_uvs == 12);
  REQUIRE(sr.stats.warnings.size() == 2);
  CHECK_THAT(sr.stats.warnings[0], Catch::Contains("bake_scene: 12 page UVs lie outside [0, 1] by at most lightmap_uv_tolerance"));
  CHECK_THAT(sr.stats.warnings[1], Catch::Contains("(the first: meshes[1] triangle 0 (scene triangle " +
                                                   std::to_string(messy.occluder_first) + "))"));
  test::require_error([&] { bake_scene(si, strict); }, status::invalid_argument,
                      "bake_scene: meshes[1] triangle 0 (scene triangle " + std::to_string(messy.occluder_first) +
                          ") has zero area in its page's UV space");
}
