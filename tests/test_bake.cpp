// Tests of bake.hpp: exact UV coverage against analytic and supersampled references, the overlap
// rule, a closed box lit by an emissive ceiling against Lambert's formula, the white furnace
// against its geometric series, dilation, indirect-only output, determinism across thread
// counts, cancellation and bad input.
#include "hemilight/bake.hpp"
#include "hemilight/reference_scenes.hpp"

#include "raycast_reference.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

using namespace hemilight;

namespace {

constexpr double pi = 3.14159265358979323846;

// A mesh with explicit UVs: triangles given as (3D, UV) vertex triples.
struct uv_mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
  std::vector<material> materials;
  void add(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec2 ua, glm::vec2 ub, glm::vec2 uc, material m = {}) {
    const auto base = std::uint32_t(positions.size());
    positions.insert(positions.end(), {a, b, c});
    uvs.insert(uvs.end(), {ua, ub, uc});
    indices.insert(indices.end(), {base, base + 1, base + 2});
    materials.push_back(m);
  }
  bake_input input() const {
    bake_input in;
    in.scene.positions = positions.data();
    in.scene.vertex_count = positions.size();
    in.scene.indices = indices.data();
    in.scene.triangle_count = indices.size() / 3;
    in.scene.materials = materials.data();
    in.scene.lightmap_uvs = uvs.data();
    return in;
  }
};

// The Cornell box with 32 x 32 chart UVs and small bake options (N = 16, 2 bounces): fast.
struct small_cornell {
  scene_mesh mesh = cornell_box();
  bake_options options;
  small_cornell() {
    generate_lightmap_uvs(mesh, 32, 2);
    options.width = options.height = 32;
    options.resolution = 16;
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
  o.resolution = 32;
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
  o.resolution = 16;
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
    o.resolution = 16;
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
  o.resolution = 8;
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
  throws_with(outside.input(), o, "lightmap_uvs[1].u = 1.5 is outside [0, 1]");
  uv_mesh flat = m;
  flat.uvs[2] = flat.uvs[1];
  throws_with(flat.input(), o, "triangle 0 has zero area in lightmap UV space");
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
