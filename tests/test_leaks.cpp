// Light leaks through walls (fixtures: leak_scenes.hpp). Two rooms sharing a wall, from a plane
// (one-sided, or two coincident quads back to back) to two texels thick, over a floor and ceiling
// whose lit and dark halves are separate charts meeting under the wall; and an inner corner of
// thin walls with a sealed pocket behind it. Each is baked with the library's default options plus
// its light, at texels of 0.25 and 0.125 m (larger than the thin walls are thick), with one and
// three bounces. Nothing reaches the dark side, so its true irradiance is exactly 0 and whatever a
// bake puts there is a leak, measured against the lit side's irradiance next to the wall:
//   - over the dark side's sampled texels within two texels of the wall, and over all of them;
//   - over bilinear lookups of the dark side's lightmap at its own UVs, at points of its visible
//     surfaces within one texel of the wall (what an engine shows: they read dilated texels too).
// The table rows (docs/bake.md, "Leaks") are printed to stdout:
//   build/tests/hemilight_tests "[leaks]" | grep '^|'
#include "hemilight/bake.hpp"
#include "hemilight/leak_scenes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

// The target the project has set: a leak of at most 1% of the lit side's irradiance next to the
// wall. The true value is 0, so this is the whole budget for leaks, not a numerical tolerance;
// where a bake keeps the dark side's own records and samples, the measured leak is below 1e-9
// (a record at the point itself weighs 1e12 against a few for a lit record across the wall).
constexpr double leak_target = 0.01;

// The texel sizes of the two lightmaps (metres): 72² and 128² for the two rooms, 64² and 112² for
// the corner.
constexpr float texel_sizes[] = {0.25f, 0.125f};

float value_at(const image& img, std::size_t k) {
  const float* p = img.pixels.data() + 3 * k;
  return (p[0] + p[1] + p[2]) / 3.0f;
}

// Bilinear lookup at uv with bake.hpp's texel convention (centres at (x + 0.5) / W), clamped to
// the edge: what an engine's sampler reads.
float bilinear(const image& img, glm::vec2 uv) {
  const float x = uv.x * float(img.width) - 0.5f, y = uv.y * float(img.height) - 0.5f;
  const float x0 = std::floor(x), y0 = std::floor(y), fx = x - x0, fy = y - y0;
  const auto at = [&](int ix, int iy) {
    ix = std::clamp(ix, 0, img.width - 1);
    iy = std::clamp(iy, 0, img.height - 1);
    return value_at(img, std::size_t(iy) * std::size_t(img.width) + std::size_t(ix));
  };
  const int ix = int(x0), iy = int(y0);
  return (1 - fy) * ((1 - fx) * at(ix, iy) + fx * at(ix + 1, iy)) + fy * ((1 - fx) * at(ix, iy + 1) + fx * at(ix + 1, iy + 1));
}

// A bake's leak: the dark side's irradiance (mean of the channels) over the mean of the lit
// side's sampled texels within two texels of a wall (covered texels, inside a wall, left out).
struct leak_figures {
  double lit_mean = 0;                 // the reference, absolute
  double near_max = 0, near_mean = 0;  // dark side, sampled texels within 2 texels of a wall
  double all_max = 0, all_mean = 0;    // dark side, all sampled texels
  double lookup_max = 0;               // dark side, bilinear lookups within 1 texel of a wall
  std::size_t lit = 0, near = 0, all = 0, dark_valid = 0, lookups = 0;
  double worst() const { return std::max({near_max, all_max, lookup_max}); }
};

leak_figures measure(const leak_scene& s, const bake_input& in, const bake_result& r) {
  const int size = s.lightmap_size;
  const float ts = s.texel_size;
  const lightmap_samples smp = compute_lightmap_samples(in, size, size);
  leak_figures f;
  double lit_sum = 0, near_sum = 0, all_sum = 0;
  for (std::size_t k = 0; k < smp.owner.size(); ++k) {
    if (!r.sampled[k]) continue;  // sampled: a sample was placed (valid or filled from its chart)
    const std::uint32_t t = smp.owner[k];
    const float d = distance_to_walls(s, smp.position[k]);
    const double e = value_at(r.irradiance, k);
    if (s.triangle_side[t] == leak_side::lit && !s.triangle_covered[t] && d <= 2.0f * ts) {
      lit_sum += e;
      ++f.lit;
    }
    if (s.triangle_side[t] != leak_side::dark) continue;
    ++f.all;
    f.dark_valid += r.valid[k];
    all_sum += e;
    f.all_max = std::max(f.all_max, e);
    if (d <= 2.0f * ts) {
      ++f.near;
      near_sum += e;
      f.near_max = std::max(f.near_max, e);
    }
  }
  // The lookups: points of the dark side's visible triangles on a grid a quarter of a texel fine,
  // those within one texel of a wall (0.5 texel from it among them), read at their own UVs.
  const scene_mesh& m = s.mesh;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    if (s.triangle_side[t] != leak_side::dark || s.triangle_covered[t]) continue;
    const std::uint32_t* idx = m.indices.data() + 3 * t;
    const glm::vec3 a = m.positions[idx[0]], b = m.positions[idx[1]], c = m.positions[idx[2]];
    const glm::vec2 ua = m.lightmap_uvs[idx[0]], ub = m.lightmap_uvs[idx[1]], uc = m.lightmap_uvs[idx[2]];
    const float longest = std::max({glm::length(b - a), glm::length(c - a), glm::length(c - b)});
    const int n = int(std::ceil(longest / (0.25f * ts)));
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const float bi = float(i) / float(n), bj = float(j) / float(n);
        const float d = distance_to_walls(s, a + bi * (b - a) + bj * (c - a));
        if (!(d > 0.0f && d <= ts)) continue;
        ++f.lookups;
        f.lookup_max = std::max(f.lookup_max, double(bilinear(r.irradiance, ua + bi * (ub - ua) + bj * (uc - ua))));
      }
  }
  f.lit_mean = f.lit ? lit_sum / double(f.lit) : 0.0;
  const double ref = f.lit_mean > 0 ? f.lit_mean : 1.0;
  f.near_mean = f.near ? near_sum / double(f.near) / ref : 0.0;
  f.all_mean = f.all ? all_sum / double(f.all) / ref : 0.0;
  f.near_max /= ref;
  f.all_max /= ref;
  f.lookup_max /= ref;
  return f;
}

// One configuration of a scene; the texel size (and a wall of `wall_texels` texels) per bake.
struct leak_case {
  const char* scene;  // "two_rooms" or "thin_wall_corner"
  const char* wall;   // how the table names the wall
  float thickness = 0.0f;
  float wall_texels = 0.0f;  // > 0: the wall is this many texels thick instead
  zero_wall plane = zero_wall::one_sided;
  bool seam = false;
  leak_light light = leak_light::point;
};

// Bakes c at texel size ts with the default options plus the scene's size, light and bounces;
// prints the table row and checks the target.
void bake_and_check(const leak_case& c, float ts, int bounces) {
  leak_scene_options o;
  o.texel_size = ts;
  o.plane = c.plane;
  o.floor_seam_under_wall = c.seam;
  o.light = c.light;
  const float t = c.wall_texels > 0.0f ? c.wall_texels * ts : c.thickness;
  const leak_scene s = std::strcmp(c.scene, "two_rooms") == 0 ? two_rooms(t, o) : thin_wall_corner(t, o);
  bake_input in;
  in.scene = s.mesh.desc();
  bake_options bo;
  bo.width = bo.height = s.lightmap_size;
  bo.bounces = bounces;
  bo.lights = s.lights;
  const bake_result r = bake_lightmap(in, bo);
  const leak_figures f = measure(s, in, r);
  const char* light = c.light == leak_light::point ? "point" : c.light == leak_light::emissive_patch ? "patch" : "window";
  std::printf("| %s | %s | %.3g m | %d² (%.3g m) | %s | %d | %.3f%% | %.3f%% | %.3f%% | %.3f%% | %.3f%% | %zu of %zu |\n", c.scene,
              c.wall, double(t), s.lightmap_size, double(ts), light, bounces, 100 * f.near_max, 100 * f.near_mean, 100 * f.all_max,
              100 * f.all_mean, 100 * f.lookup_max, f.dark_valid, f.all);
  std::fflush(stdout);
  INFO(c.scene << ", " << c.wall << " (" << t << " m), " << s.lightmap_size << "² (texel " << ts << " m), " << light << ", "
                << bounces << " bounce(s); lit side next to the wall " << f.lit_mean << " over " << f.lit << " texels");
  // The measurement sees what it should: a lit side, dark texels by the wall, lookups.
  REQUIRE(f.lit_mean > 0.05);
  REQUIRE(f.near > 0);
  REQUIRE(f.lookups > 0);
  INFO("dark side: max " << 100 * f.near_max << "% (mean " << 100 * f.near_mean << "%) within two texels of the wall, max "
                         << 100 * f.all_max << "% (mean " << 100 * f.all_mean << "%) over all " << f.all << " sampled texels ("
                         << f.dark_valid << " valid), bilinear lookups within a texel of the wall max " << 100 * f.lookup_max
                         << "% (" << f.lookups << ")");
  CHECK(f.near_max <= leak_target);
  CHECK(f.all_max <= leak_target);
  CHECK(f.lookup_max <= leak_target);
}

void bake_and_check(const leak_case& c, std::initializer_list<int> bounces) {
  for (float ts : texel_sizes)
    for (int b : bounces) bake_and_check(c, ts, b);
}

}  // namespace

// ---- the fixtures ------------------------------------------------------------------------------

TEST_CASE("Leak scenes: charts apart, the floor seam under the wall, deterministic, bad options refused", "[leaks]") {
  leak_scene_options o;
  o.plane = zero_wall::back_to_back;
  for (const leak_scene& s : {two_rooms(0.0f, o), two_rooms(0.05f), thin_wall_corner(0.0f, o), thin_wall_corner(0.25f)}) {
    bake_input in;
    in.scene = s.mesh.desc();
    const lightmap_samples smp = compute_lightmap_samples(in, s.lightmap_size, s.lightmap_size);
    CHECK(smp.overlapping_texels == 0);
    CHECK(smp.degenerate_triangles == 0);
    CHECK(smp.no_uv_area_triangles == 0);
    REQUIRE(s.triangle_side.size() == s.mesh.triangle_count());
    REQUIRE(s.triangle_covered.size() == s.mesh.triangle_count());
    // The true irradiance of the dark side is 0: nothing there emits.
    for (std::size_t t = 0; t < s.mesh.triangle_count(); ++t)
      if (s.triangle_side[t] == leak_side::dark) CHECK(s.mesh.materials[t].emission == glm::vec3(0.0f));
  }
  // Two rooms over a plane: the lit and the dark floor meet at x = 0 with the same vertex
  // positions (a shared edge, coplanar) and different lightmap UVs (two charts): the seam.
  const leak_scene s = two_rooms(0.0f);
  const scene_mesh& m = s.mesh;
  std::size_t seam_vertices = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (std::size_t u = 0; u < m.triangle_count(); ++u) {
      if (s.triangle_side[t] != leak_side::lit || s.triangle_side[u] != leak_side::dark) continue;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const std::uint32_t a = m.indices[3 * t + std::size_t(i)], b = m.indices[3 * u + std::size_t(j)];
          if (m.positions[a] == m.positions[b] && m.positions[a].x == 0.0f && m.positions[a].y == 0.0f) {
            ++seam_vertices;
            CHECK(m.lightmap_uvs[a] != m.lightmap_uvs[b]);
          }
        }
    }
  CHECK(seam_vertices > 0);
  // The same options give the same bytes.
  const leak_scene again = two_rooms(0.0f);
  CHECK(again.mesh.positions == m.positions);
  CHECK(again.mesh.indices == m.indices);
  CHECK(again.mesh.lightmap_uvs == m.lightmap_uvs);
  CHECK(again.lightmap_size == s.lightmap_size);
  leak_scene_options bad;
  bad.texel_size = 0.0f;
  CHECK_THROWS_AS(two_rooms(0.0f, bad), error);
  CHECK_THROWS_AS(thin_wall_corner(-0.1f), error);
  CHECK_THROWS_AS(thin_wall_corner(2.0f), error);
}

// ---- two rooms ---------------------------------------------------------------------------------

TEST_CASE("Leaks: two rooms, walls 0.02 m, 0.05 m and two texels thick: the dark room stays dark", "[leaks]") {
  bake_and_check({"two_rooms", "slab 0.02 m", 0.02f}, {1, 3});
  bake_and_check({"two_rooms", "slab 0.05 m", 0.05f}, {1, 3});
  bake_and_check({"two_rooms", "slab 2 texels", 0.0f, 2.0f}, {1, 3});
}

// The floors and ceilings of both rooms run under the wall to its middle plane, where the lit and
// the dark half meet as coplanar triangles in separate charts (a seam that stitching would join).
TEST_CASE("Leaks: two rooms, floor and ceiling seam under a 0.02 m and a two-texel wall", "[leaks]") {
  leak_case c{"two_rooms", "slab 0.02 m, floor seam", 0.02f};
  c.seam = true;
  bake_and_check(c, {1, 3});
  c = {"two_rooms", "slab 2 texels, floor seam", 0.0f, 2.0f};
  c.seam = true;
  bake_and_check(c, {1, 3});
}

// A wall of zero thickness always has the floor seam under it (the floors meet at x = 0). The dark
// room's texels near it see its back face (the plane's, or that of the lit side's quad, which
// wins the depth tie with its coincident twin): they are invalid, and are filled from the valid
// texels of their own chart, never across the atlas's padding from a lit chart (bake.md, "Leaks").
TEST_CASE("Leaks: two rooms, a zero-thickness wall over the floor seam, direct light (one bounce)", "[leaks]") {
  bake_and_check({"two_rooms", "plane, one-sided, floor seam", 0.0f}, {1});
  bake_and_check({"two_rooms", "plane, back to back, floor seam", 0.0f, 0.0f, zero_wall::back_to_back}, {1});
}

// The dark room's samples within a few texels of the plane see its back face over more than 10%
// of their hemicube and are invalid, so they make no records; the dark points between them lie
// within the reach of the lit room's records across the plane (floor and ceiling are coplanar
// across it, same normal, a reach of at least a x min_radius = 2 texels). The cache's segment
// test (cache_run::segment_blocked) keeps those records off them: without it, 62-65%.
TEST_CASE("Leaks: two rooms, one-sided zero-thickness wall, three bounces", "[leaks]") {
  bake_and_check({"two_rooms", "plane, one-sided, floor seam", 0.0f}, {3});
}

// As the one-sided plane: the lit side's quad comes first in the mesh and wins the depth tie with
// its coincident twin, so the dark room sees its back face (with the dark side's quad first it is
// the lit room whose texels turn invalid: no leak, but the lit room loses 40% of its light near the
// wall). Without the cache's segment test, 62-65%.
TEST_CASE("Leaks: two rooms, back-to-back zero-thickness wall, three bounces", "[leaks]") {
  bake_and_check({"two_rooms", "plane, back to back, floor seam", 0.0f, 0.0f, zero_wall::back_to_back}, {3});
}

// The same interpolation across the plane as above, from the first pass on, because the
// hemicubes see the emitter: 144-147% at one bounce without the cache's segment test.
TEST_CASE("Leaks: two rooms, one-sided zero-thickness wall, emissive patch, one bounce", "[leaks]") {
  leak_case c{"two_rooms", "plane, one-sided, floor seam", 0.0f};
  c.light = leak_light::emissive_patch;
  bake_and_check(c, {1});
}

TEST_CASE("Leaks: two rooms lit by an emissive patch the hemicubes see, walls 0.02 m and two texels", "[leaks]") {
  leak_case c{"two_rooms", "slab 0.02 m, floor seam", 0.02f};
  c.seam = true;
  c.light = leak_light::emissive_patch;
  bake_and_check(c, {1});
  c = {"two_rooms", "slab 2 texels", 0.0f, 2.0f};
  c.light = leak_light::emissive_patch;
  bake_and_check(c, {1});
}

// ---- the inner corner ------------------------------------------------------------------------

TEST_CASE("Leaks: an inner corner of walls 0.02 m, 0.05 m and two texels thick: the pocket stays dark", "[leaks]") {
  bake_and_check({"thin_wall_corner", "slab 0.02 m", 0.02f}, {1, 3});
  leak_case c{"thin_wall_corner", "slab 0.05 m, floor seam", 0.05f};
  c.seam = true;
  bake_and_check(c, {1, 3});
  bake_and_check({"thin_wall_corner", "slab 2 texels", 0.0f, 2.0f}, {1, 3});
}

// Measured 0.13% at 0.125 m texels: the room's wall at x = 4 runs on, coplanar, on both sides of
// the 0.02 m wall's end, and a lit record on it reaches a pocket point near the ceiling that its
// own records leave covered by it at the rim of its reach (with a hemicube per texel: 0).
TEST_CASE("Leaks: an inner corner lit by an emissive patch the hemicubes see, walls 0.02 m and two texels", "[leaks]") {
  leak_case c{"thin_wall_corner", "slab 0.02 m", 0.02f};
  c.light = leak_light::emissive_patch;
  bake_and_check(c, {1});
  c = {"thin_wall_corner", "slab 2 texels", 0.0f, 2.0f};
  c.light = leak_light::emissive_patch;
  bake_and_check(c, {1});
}

TEST_CASE("Leaks: an inner corner of zero-thickness walls, direct light (one bounce)", "[leaks]") {
  bake_and_check({"thin_wall_corner", "plane, one-sided", 0.0f}, {1});
  bake_and_check({"thin_wall_corner", "plane, back to back", 0.0f, 0.0f, zero_wall::back_to_back}, {1});
}

// The mechanism of the two rooms' planes (the pocket's samples near the planes are invalid, the
// lit side's records reach the points between them): 90-91% without the cache's segment test.
TEST_CASE("Leaks: an inner corner of one-sided zero-thickness walls, three bounces", "[leaks]") {
  bake_and_check({"thin_wall_corner", "plane, one-sided", 0.0f}, {3});
}

// As above: 66-80% without the cache's segment test.
TEST_CASE("Leaks: an inner corner of back-to-back zero-thickness walls, three bounces", "[leaks]") {
  bake_and_check({"thin_wall_corner", "plane, back to back", 0.0f, 0.0f, zero_wall::back_to_back}, {3});
}

// ---- more lights, not run by default (about 40 s) --------------------------------------------

TEST_CASE("Leaks: the window and the emissive patch over every wall", "[.leaks_lights]") {
  for (leak_light l : {leak_light::emissive_patch, leak_light::window})
    for (const char* scene : {"two_rooms", "thin_wall_corner"}) {
      leak_case cases[] = {{scene, "plane, one-sided", 0.0f},
                           {scene, "plane, back to back", 0.0f, 0.0f, zero_wall::back_to_back},
                           {scene, "slab 0.02 m", 0.02f},
                           {scene, "slab 0.02 m, floor seam", 0.02f, 0.0f, zero_wall::one_sided, true},
                           {scene, "slab 2 texels", 0.0f, 2.0f},
                           {scene, "slab 2 texels, floor seam", 0.0f, 2.0f, zero_wall::one_sided, true}};
      for (leak_case& c : cases) {
        c.light = l;
        bake_and_check(c, {1, 3});
      }
    }
}
