// Tests of bake.hpp's scene bakes (bake_scene): pages against bakes of each page alone and
// against a single-lightmap bake of the same geometry, occluder-only meshes against Lambert's
// closed form and exact sun shadows, the occluders' radiance modes, per-page albedo and emission
// images against per-triangle values and the white furnace's closed form, determinism across
// thread counts, and bad input named by page and mesh.
#include "hemilight/bake.hpp"

#include "raycast_reference.hpp"
#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

using namespace hemilight;

namespace {

constexpr double pi = 3.14159265358979323846;

// Several meshes with their own lightmap UVs in one scene: the arrays bake_scene reads.
struct multi_mesh {
  scene_mesh all;
  std::vector<bake_mesh> meshes;
  void add(const scene_mesh& m, int page, glm::vec2 scale = glm::vec2(1.0f), glm::vec2 offset = glm::vec2(0.0f)) {
    const auto base = std::uint32_t(all.positions.size());
    bake_mesh bm;
    bm.first_triangle = all.triangle_count();
    bm.triangle_count = m.triangle_count();
    bm.page = page;
    bm.uv_scale = scale;
    bm.uv_offset = offset;
    meshes.push_back(bm);
    all.positions.insert(all.positions.end(), m.positions.begin(), m.positions.end());
    for (std::uint32_t i : m.indices) all.indices.push_back(base + i);
    all.materials.insert(all.materials.end(), m.materials.begin(), m.materials.end());
    if (m.lightmap_uvs.empty()) all.lightmap_uvs.resize(all.positions.size(), glm::vec2(0.0f));
    else all.lightmap_uvs.insert(all.lightmap_uvs.end(), m.lightmap_uvs.begin(), m.lightmap_uvs.end());
  }
  scene_bake_input input(std::vector<lightmap_page> pages, glm::vec3 sky = glm::vec3(0.0f)) const {
    scene_bake_input in;
    in.geometry.scene = all.desc();
    in.geometry.scene.sky_radiance = sky;
    in.pages = std::move(pages);
    in.meshes = meshes;
    return in;
  }
};

lightmap_page page_of(int w, int h) {
  lightmap_page p;
  p.width = w;
  p.height = h;
  return p;
}

bake_input input_of(const scene_mesh& m, glm::vec3 sky) {
  bake_input in;
  in.scene = m.desc();
  in.scene.sky_radiance = sky;
  return in;
}

// An L: a unit floor (y = 0, normal +y) and a unit wall (x = 0, normal +x), 2 x 2 grids each.
scene_mesh floor_mesh(const material& m) {
  scene_mesh s;
  s.add_grid({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, 2, 2, m);
  return s;
}
scene_mesh wall_mesh(const material& m) {
  scene_mesh s;
  s.add_grid({0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}, 2, 2, m);
  return s;
}
scene_mesh l_shape(const material& m) {
  scene_mesh s = floor_mesh(m);
  const scene_mesh w = wall_mesh(m);
  const auto base = std::uint32_t(s.positions.size());
  s.positions.insert(s.positions.end(), w.positions.begin(), w.positions.end());
  for (std::uint32_t i : w.indices) s.indices.push_back(base + i);
  s.materials.insert(s.materials.end(), w.materials.begin(), w.materials.end());
  return s;
}

// m turned by 180 degrees about z (a rotation: windings and front faces are kept) and moved by t.
scene_mesh turned(scene_mesh m, glm::vec3 t) {
  for (glm::vec3& p : m.positions) p = glm::vec3(-p.x, -p.y, p.z) + t;
  return m;
}

// Largest |a - b| / max(|b|, floor) over all texels (sampled and dilated) of two bakes of the same grid.
double worst_relative(const bake_result& a, const bake_result& b, double floor_value) {
  REQUIRE(a.irradiance.pixels.size() == b.irradiance.pixels.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < a.sampled.size(); ++k)
      for (std::size_t c = 0; c < 3; ++c) {
        const double x = a.irradiance.pixels[3 * k + c], y = b.irradiance.pixels[3 * k + c];
        worst = std::max(worst, std::fabs(x - y) / std::max(std::fabs(y), floor_value));
      }
  return worst;
}

bake_options reference_options() {
  bake_options o;
  o.sampler.resolution = 32;
  o.bounces = 2;
  o.use_cache = false;  // a hemicube per texel: no interpolation between the two bakes' records
  o.thread_count = 2;
  return o;
}

}  // namespace

TEST_CASE("Scene bake: two meshes on two pages give the texels of each baked alone where they do not see each other", "[bake][bake_scene]") {
  material grey;
  grey.albedo = glm::vec3(0.5f);
  // A sky-lit L whose wall bounces light onto its floor, and the same L turned by 180 degrees
  // below and behind it: each sees only its own half-space (x > 0, y > 0 and x < -2, y < -2).
  scene_mesh a = l_shape(grey), b = turned(l_shape(grey), {-2.0f, -2.0f, 0.0f});
  generate_lightmap_uvs(a, 32, 2);
  generate_lightmap_uvs(b, 24, 2);  // a narrower page: the atlas has a guard column beside it
  multi_mesh mm;
  mm.add(a, 0);
  mm.add(b, 1);
  const glm::vec3 sky(1.0f, 0.5f, 0.25f);
  bake_options o = reference_options();
  const scene_bake_result r = bake_scene(mm.input({page_of(32, 32), page_of(24, 24)}, sky), o);
  REQUIRE(r.pages.size() == 2);
  int size = 32;
  for (const scene_mesh* m : {&a, &b}) {
    const std::size_t p = m == &a ? 0 : 1;
    o.width = o.height = size;
    const bake_result alone = bake_lightmap(input_of(*m, sky), o);
    const bake_result& got = r.pages[p];
    REQUIRE(got.irradiance.width == size);
    REQUIRE(got.irradiance.height == size);
    // The samples are computed in the page's own grid: coverage and sample flags are identical.
    CHECK(got.coverage == alone.coverage);
    CHECK(got.sampled == alone.sampled);
    CHECK(got.valid == alone.valid);
    CHECK(got.stats.sampled_texels == alone.stats.sampled_texels);
    CHECK(got.stats.dilated_texels == alone.stats.dilated_texels);
    // The hemicubes differ only in float rounding: the bounce lookups go through atlas UVs
    // (another scale), and the near plane grows with the scene (1e-4 of its size, still far
    // below every texel's distance to the other surface here): measured < 1e-6, so 1e-5.
    const double worst = worst_relative(got, alone, 1e-3);
    INFO("page " << p << ": worst relative difference to the bake alone " << worst);
    CHECK(worst < 1e-5);
    size = 24;
  }
  CHECK(r.stats.texels == 32 * 32 + 24 * 24);
  CHECK(r.stats.sampled_texels == r.pages[0].stats.sampled_texels + r.pages[1].stats.sampled_texels);
}

TEST_CASE("Scene bake: light bounces between pages as in a single-lightmap bake of the same geometry", "[bake][bake_scene]") {
  material grey;
  grey.albedo = glm::vec3(0.5f);
  // The floor in the left half of a 64 x 32 lightmap, the wall in the right half, each chart 4
  // texels from the middle; as pages: each half a 32 x 32 page (scale (2, 1), offsets 0 and -1:
  // the texel grids coincide exactly).
  scene_mesh floor = floor_mesh(grey), wall = wall_mesh(grey);
  const auto place = [](scene_mesh& m, float u0) {
    m.lightmap_uvs.resize(m.positions.size());
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      const glm::vec3 p = m.positions[i];
      const float s = p.x == 0.0f && p.y != 0.0f ? p.y : p.x;  // floor: x; wall: y (the 3 x 3 grid's first axis)
      const float t = p.z;
      m.lightmap_uvs[i] = glm::vec2(u0 + (4.0f + 24.0f * s) / 64.0f, (4.0f + 24.0f * t) / 32.0f);
    }
  };
  place(floor, 0.0f);
  place(wall, 0.5f);
  scene_mesh single = floor;
  {
    multi_mesh both;
    both.add(floor, 0);
    both.add(wall, 0);
    single = both.all;
  }
  bake_options o = reference_options();
  o.dilation = 2;  // dilated rings stay clear of the middle line in the single lightmap
  o.width = 64;
  o.height = 32;
  const glm::vec3 sky(1.0f);
  const bake_result one = bake_lightmap(input_of(single, sky), o);

  multi_mesh mm;
  mm.add(floor, 0, {2.0f, 1.0f}, {0.0f, 0.0f});
  mm.add(wall, 1, {2.0f, 1.0f}, {-1.0f, 0.0f});
  const scene_bake_result r = bake_scene(mm.input({page_of(32, 32), page_of(32, 32)}, sky), o);
  // The page results are the halves of the single lightmap.
  double worst = 0.0, bounce = 0.0;
  o.bounces = 1;
  const bake_result direct = bake_lightmap(input_of(single, sky), o);
  std::size_t compared = 0;
  for (int p = 0; p < 2; ++p)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const std::size_t k = std::size_t(y) * 32 + std::size_t(x), k1 = std::size_t(y) * 64 + std::size_t(x + 32 * p);
        REQUIRE(r.pages[std::size_t(p)].sampled[k] == one.sampled[k1]);
        if (!one.sampled[k1]) continue;
        ++compared;
        const double got = r.pages[std::size_t(p)].irradiance.pixels[3 * k], want = one.irradiance.pixels[3 * k1];
        worst = std::max(worst, std::fabs(got - want) / want);
        bounce = std::max(bounce, want - direct.irradiance.pixels[3 * k1]);
      }
  INFO("texels compared " << compared << ", worst relative difference " << worst << ", largest bounce " << bounce);
  REQUIRE(compared > 900);
  // The bounce is real (each surface sees the other: up to ~0.2 of pi here) ...
  CHECK(bounce > 0.05);
  // ... and the same: only float rounding of the atlas UVs in the bilinear lookups differs
  // (measured < 1e-6); 1e-5.
  CHECK(worst < 1e-5);
}

TEST_CASE("Scene bake: an occluder-only mesh shadows the sky as Lambert's formula says and gets no texels", "[bake][bake_scene]") {
  material grey;
  grey.albedo = glm::vec3(0.5f);
  scene_mesh floor;
  floor.add_grid({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 4, 4, grey);
  generate_lightmap_uvs(floor, 48, 2);
  // A black square 0.5 above the floor, its front facing down (occluder only, no UVs).
  scene_mesh roof;
  roof.add_quad({-0.3f, 0.5f, -0.3f}, {0.3f, 0.5f, -0.3f}, {0.3f, 0.5f, 0.3f}, {-0.3f, 0.5f, 0.3f}, material{});
  multi_mesh mm;
  mm.add(floor, 0);
  mm.add(roof, -1);
  bake_options o;
  o.sampler.resolution = 64;
  o.bounces = 1;
  o.use_cache = false;
  o.thread_count = 2;
  const scene_bake_result r = bake_scene(mm.input({page_of(48, 48)}, glm::vec3(1.0f)), o);
  const bake_result& page = r.pages[0];
  const lightmap_samples s = compute_lightmap_samples(input_of(floor, glm::vec3(1.0f)), 48, 48);
  const std::vector<glm::dvec3> square = {{-0.3, 0.5, -0.3}, {0.3, 0.5, -0.3}, {0.3, 0.5, 0.3}, {-0.3, 0.5, 0.3}};
  double worst = 0.0, darkest = pi;
  int count = 0;
  for (std::size_t k = 0; k < page.sampled.size(); ++k) {
    if (!page.sampled[k]) continue;
    // Sky L = 1 over the hemisphere less the square's part: E = pi - n . Phi(square).
    const double ref = pi - test::polygon_vector_irradiance(square, glm::dvec3(s.position[k]), 1.0).y;
    worst = std::max(worst, std::fabs(page.irradiance.pixels[3 * k] - ref) / ref);
    darkest = std::min(darkest, ref);
    ++count;
  }
  INFO("floor texels " << count << ", darkest reference " << darkest << ", worst relative error " << worst);
  REQUIRE(count > 1000);
  CHECK(darkest < 0.75 * pi);  // the shadow is deep (a third of the sky below the square)
  // Hemicube at N = 64: exact weights; the square's edges are discretised at texel centres,
  // which is < 1% of the irradiance here (the same bound as the emissive-ceiling box test).
  CHECK(worst < 0.01);
  CHECK(r.stats.sampled_texels == page.stats.sampled_texels);
}

TEST_CASE("Scene bake: an occluder-only mesh casts an exact sun shadow through the shadow rays", "[bake][bake_scene][lights]") {
  material grey;
  grey.albedo = glm::vec3(0.5f);
  scene_mesh floor;
  floor.add_grid({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 2, 2, grey);
  generate_lightmap_uvs(floor, 40, 2);
  scene_mesh roof;
  roof.add_quad({-0.3f, 0.5f, -0.3f}, {0.3f, 0.5f, -0.3f}, {0.3f, 0.5f, 0.3f}, {-0.3f, 0.5f, 0.3f}, material{});
  multi_mesh mm;
  mm.add(floor, 0);
  mm.add(roof, -1);
  bake_options o;
  o.sampler.resolution = 16;
  o.thread_count = 2;
  light sun;
  sun.type = light_type::directional;
  sun.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  sun.color = glm::vec3(2.0f);
  o.lights.push_back(sun);
  const scene_bake_result r = bake_scene(mm.input({page_of(40, 40)}), o);
  const lightmap_samples s = compute_lightmap_samples(input_of(floor, glm::vec3(0.0f)), 40, 40);
  int lit = 0, shadowed = 0;
  for (std::size_t k = 0; k < s.position.size(); ++k) {
    if (!r.pages[0].sampled[k]) continue;
    const glm::vec3 q = s.position[k];
    const float e = r.pages[0].irradiance.pixels[3 * k];
    // Straight down: the shadow is the square's footprint. Hard light: exactly 0 or exactly the
    // light's irradiance (the floor's bounce is not seen by an upward floor; the roof is black).
    if (std::fabs(q.x) < 0.29f && std::fabs(q.z) < 0.29f) {
      CHECK(e == 0.0f);
      ++shadowed;
    } else if (std::fabs(q.x) > 0.31f || std::fabs(q.z) > 0.31f) {
      CHECK(e == Approx(2.0f).epsilon(1e-6));
      ++lit;
    }
  }
  CHECK(shadowed > 50);
  CHECK(lit > 500);
}

TEST_CASE("Scene bake: occluders' radiance modes against the occluder baked on its own page", "[bake][bake_scene]") {
  // A bright floor under the sky and a white square above it: what the square's underside sends
  // back down is what the occluder modes approximate. Measured here (docs/bake.md quotes it).
  material white;
  white.albedo = glm::vec3(0.8f);
  scene_mesh floor;
  floor.add_grid({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 2, 2, white);
  generate_lightmap_uvs(floor, 32, 2);
  scene_mesh roof;
  roof.add_quad({-0.4f, 0.4f, -0.4f}, {0.4f, 0.4f, -0.4f}, {0.4f, 0.4f, 0.4f}, {-0.4f, 0.4f, 0.4f}, white);
  scene_mesh roof_uv = roof;
  generate_lightmap_uvs(roof_uv, 16, 2);
  bake_options o = reference_options();
  o.sampler.resolution = 32;
  o.bounces = 3;
  const glm::vec3 sky(1.0f);
  multi_mesh baked;
  baked.add(floor, 0);
  baked.add(roof_uv, 1);
  const scene_bake_result ref = bake_scene(baked.input({page_of(32, 32), page_of(16, 16)}, sky), o);
  multi_mesh occluded;
  occluded.add(floor, 0);
  occluded.add(roof, -1);
  scene_bake_input in = occluded.input({page_of(32, 32)}, sky);
  const scene_bake_result black = bake_scene(in, o);
  in.occluders = occluder_radiance::emission_plus_mean_bounce;
  const scene_bake_result mean = bake_scene(in, o);
  // Mean over the floor texels under the square (|x|, |z| < 0.4) and over all of them.
  const lightmap_samples s = compute_lightmap_samples(input_of(floor, sky), 32, 32);
  const auto stats = [&](const bake_result& r, bool under) {
    double sum = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < r.sampled.size(); ++k) {
      if (!r.sampled[k]) continue;
      const glm::vec3 q = s.position[k];
      if (under != (std::fabs(q.x) < 0.4f && std::fabs(q.z) < 0.4f)) continue;
      sum += r.irradiance.pixels[3 * k];
      ++n;
    }
    return sum / n;
  };
  const double ref_under = stats(ref.pages[0], true), black_under = stats(black.pages[0], true), mean_under = stats(mean.pages[0], true);
  const double ref_out = stats(ref.pages[0], false), black_out = stats(black.pages[0], false), mean_out = stats(mean.pages[0], false);
  const double black_err = (black_under - ref_under) / ref_under, mean_err = (mean_under - ref_under) / ref_under;
  WARN("floor under the occluder: baked " << ref_under << ", emission only " << black_under << " (" << 100 * black_err
       << "%), emission + mean bounce " << mean_under << " (" << 100 * mean_err << "%); elsewhere: baked " << ref_out
       << ", emission only " << black_out << ", mean " << mean_out);
  // Emission only never adds light: every hemicube texel sees at most what it sees in the
  // reference, so the floor is darker (per-texel hemicubes: a monotone function of the radiance).
  CHECK(black_under < ref_under);
  CHECK(black_out <= ref_out * (1.0 + 1e-6));
  // And the reflected light is a real part of it here (> 2%), which is what the measurement is for.
  CHECK(black_err < -0.02);
}

TEST_CASE("Scene bake: per-page images equal to the triangles' values give the same bake; a furnace of images matches its series", "[bake][bake_scene]") {
  SECTION("an albedo image equal to the triangles' albedo gives bitwise the same lightmap") {
    material grey;
    grey.albedo = glm::vec3(0.5f, 0.25f, 0.75f);
    scene_mesh a = l_shape(grey);
    generate_lightmap_uvs(a, 32, 2);
    multi_mesh mm;
    mm.add(a, 0);
    bake_options o;
    o.sampler.resolution = 16;
    o.bounces = 3;
    o.thread_count = 2;
    scene_bake_input in = mm.input({page_of(32, 32)}, glm::vec3(1.0f));
    const scene_bake_result plain = bake_scene(in, o);
    in.pages[0].albedo = image::make(32, 32, 3);
    for (std::size_t k = 0; k < 32 * 32; ++k) std::memcpy(in.pages[0].albedo.pixels.data() + 3 * k, &grey.albedo, sizeof(glm::vec3));
    const scene_bake_result imaged = bake_scene(in, o);
    // The same per-texel albedo gives the same radiance textures, value for value.
    CHECK(imaged.pages[0].irradiance.pixels == plain.pages[0].irradiance.pixels);
    // And a one-page scene bake of one mesh is bake_lightmap: bitwise.
    o.width = o.height = 32;
    const bake_result lm = bake_lightmap(input_of(a, glm::vec3(1.0f)), o);
    CHECK(plain.pages[0].irradiance.pixels == lm.irradiance.pixels);
  }
  SECTION("a closed room of black triangles with emission and albedo images: E = pi Le (1 + a + a^2)") {
    // Closed 1 x 1 x 1 room, faces inward, triangles black: all light and reflectance come from
    // the images. Pass k sees Le (1 + ... + a^(k-1)) everywhere (the white furnace).
    scene_mesh room;
    room.add_box({0, 0, 0}, {1, 1, 1}, material{}, true);
    generate_lightmap_uvs(room, 32, 2);
    multi_mesh mm;
    mm.add(room, 0);
    const float le = 2.0f, a = 0.6f;
    scene_bake_input in = mm.input({page_of(32, 32)});
    in.pages[0].emission = image::make(32, 32, 3, le);
    in.pages[0].albedo = image::make(32, 32, 3, a);
    bake_options o;
    o.sampler.resolution = 16;
    o.bounces = 3;
    o.thread_count = 2;
    const scene_bake_result r = bake_scene(in, o);
    const double expected = pi * le * (1.0 + a + double(a) * a);
    double worst = 0.0;
    for (std::size_t k = 0; k < r.pages[0].sampled.size(); ++k)
      if (r.pages[0].sampled[k])
        for (std::size_t c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(r.pages[0].irradiance.pixels[3 * k + c] - expected));
    INFO("worst |E - closed form| " << worst << " of " << expected);
    // Every hemicube texel sees the same radiance: only the float sums of the hemicube weights
    // and float rounding remain (the furnace test of bake_lightmap uses the same bound).
    CHECK(worst < 1e-5 * expected);
    // Without the emission image the room is dark: the image is what lights it.
    in.pages[0].emission = image{};
    const scene_bake_result dark = bake_scene(in, o);
    CHECK(*std::max_element(dark.pages[0].irradiance.pixels.begin(), dark.pages[0].irradiance.pixels.end()) == 0.0f);
  }
}

TEST_CASE("Scene bake: bitwise identical for 1 and 2 threads with pages, occluders and the cache", "[bake][bake_scene]") {
  material grey;
  grey.albedo = glm::vec3(0.5f);
  scene_mesh floor = floor_mesh(grey), wall = wall_mesh(grey);
  generate_lightmap_uvs(floor, 24, 2);
  generate_lightmap_uvs(wall, 16, 2);
  scene_mesh roof;
  roof.add_quad({0.2f, 0.6f, 0.2f}, {0.6f, 0.6f, 0.2f}, {0.6f, 0.6f, 0.6f}, {0.2f, 0.6f, 0.6f}, grey);
  multi_mesh mm;
  mm.add(floor, 0);
  mm.add(roof, -1);
  mm.add(wall, 1);
  scene_bake_input in = mm.input({page_of(24, 24), page_of(16, 16)}, glm::vec3(1.0f));
  in.occluders = occluder_radiance::emission_plus_mean_bounce;
  bake_options o;
  o.sampler.resolution = 16;
  o.bounces = 2;
  o.thread_count = 1;
  const scene_bake_result one = bake_scene(in, o);
  o.thread_count = 2;
  const scene_bake_result two = bake_scene(in, o);
  for (std::size_t p = 0; p < 2; ++p) CHECK(one.pages[p].irradiance.pixels == two.pages[p].irradiance.pixels);
}

TEST_CASE("Scene bake: bad pages, meshes and images name the page or mesh", "[bake][bake_scene]") {
  material grey;
  grey.albedo = glm::vec3(0.5f);
  scene_mesh floor = floor_mesh(grey), wall = wall_mesh(grey);
  generate_lightmap_uvs(floor, 16, 2);
  generate_lightmap_uvs(wall, 16, 2);
  multi_mesh mm;
  mm.add(floor, 0);
  mm.add(wall, 1);
  const scene_bake_input good = mm.input({page_of(16, 16), page_of(16, 16)}, glm::vec3(1.0f));
  bake_options o;
  o.sampler.resolution = 8;
  const auto fails = [&](const scene_bake_input& in, const std::string& needle, bool strict = false) {
    bake_options so = o;
    so.strict = strict;
    test::require_error([&] { bake_scene(in, so); }, status::invalid_argument, needle);
  };
  {
    scene_bake_input in = good;
    in.pages.clear();
    fails(in, "bake_scene: there are no pages");
  }
  {
    scene_bake_input in = good;
    in.meshes[1].page = 2;
    fails(in, "bake_scene: meshes[1].page = 2 is not -1 (occluder only) or a page index (2 pages)");
  }
  {
    scene_bake_input in = good;
    in.meshes[1].uv_offset = glm::vec2(0.5f, 0.0f);
    fails(in, "bake_scene: meshes[1] (page 1): lightmap_uvs[");
    fails(in, "* uv_scale + uv_offset = (");
  }
  {
    scene_bake_input in = good;
    in.meshes[0].uv_scale = glm::vec2(std::nanf(""), 1.0f);
    fails(in, "bake_scene: meshes[0]: uv_scale (nan, 1) or uv_offset (0, 0) is not finite");
  }
  {
    scene_bake_input in = good;
    in.meshes[0].uv_scale = glm::vec2(0.0f, 1.0f);
    fails(in, "bake_scene: meshes[0] triangle 0 (scene triangle 0) has zero area in its page's UV space", true);
    // Without strict the mesh's triangles occlude, get no texels and are named in a warning.
    const scene_bake_result r = bake_scene(in, o);
    CHECK(r.stats.no_uv_area_triangles == floor.triangle_count());
    CHECK(r.stats.first_no_uv_area_triangle == 0);
    REQUIRE(r.stats.warnings.size() == 1);
    CHECK_THAT(r.stats.warnings[0], Catch::Contains("bake_scene: " + std::to_string(floor.triangle_count()) +
                                                    " triangles have 3D area but no lightmap UV area (the first: meshes[0] "
                                                    "triangle 0 (scene triangle 0))"));
    CHECK(r.pages[0].stats.sampled_texels == 0);
  }
  {
    scene_bake_input in = good;
    in.meshes[1].first_triangle += 1;
    fails(in, "bake_scene: meshes[1].first_triangle = 9 must be 8");
  }
  {
    scene_bake_input in = good;
    in.meshes.pop_back();
    fails(in, "bake_scene: the meshes cover 8 of the scene's 16 triangles");
  }
  {
    scene_bake_input in = good;
    in.meshes[1].triangle_count = 9;
    fails(in, "bake_scene: meshes[1]: triangles [8, 17) run past the scene's 16 triangles");
  }
  {
    scene_bake_input in = good;
    in.pages[1].width = 0;
    fails(in, "bake_scene: pages[1]: lightmap size 0 x 16 is invalid");
  }
  {
    scene_bake_input in = good;
    in.pages[1].albedo = image::make(16, 8, 3, 0.5f);
    fails(in, "bake_scene: pages[1].albedo is 16 x 8 with 3 channels: it must be 16 x 16 RGB");
  }
  {
    scene_bake_input in = good;
    in.pages[0].albedo = image::make(16, 16, 3, 0.5f);
    in.pages[0].albedo.at(3, 7)[1] = 1.5f;
    fails(in, "bake_scene: pages[0].albedo (3, 7) = 1.5 is outside [0, 1]");
  }
  {
    scene_bake_input in = good;
    in.pages[0].emission = image::make(16, 16, 3, 1.0f);
    in.pages[0].emission.at(2, 1)[0] = -1.0f;
    fails(in, "bake_scene: pages[0].emission (2, 1) = -1 is outside [0, ");
  }
  {
    // Only occluders: nothing to bake.
    scene_bake_input in = good;
    in.meshes[0].page = in.meshes[1].page = -1;
    fails(in, "bake_scene: no texel is covered by a triangle");
  }
  // Raw UVs may lie outside [0, 1] when the scale and offset bring them in.
  {
    multi_mesh shifted;
    scene_mesh f = floor;
    for (glm::vec2& uv : f.lightmap_uvs) uv += glm::vec2(3.0f, -2.0f);
    shifted.add(f, 0, glm::vec2(1.0f), glm::vec2(-3.0f, 2.0f));
    CHECK_NOTHROW(bake_scene(shifted.input({page_of(16, 16)}, glm::vec3(1.0f)), o));
  }
}
