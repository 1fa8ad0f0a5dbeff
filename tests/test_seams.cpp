// Tests of seams.hpp and the baker's seam stitching: the step measured along a seam against its
// closed form (two charts of constant values), the seam search's classes (one chart, T-junctions,
// creases, walls), stitching against the unstitched bake and a converged reference (within one
// lightmap, across pages of a scene bake, in the directional maps and the shadow mask), seams
// under walls left alone, and bad input.
#include "hemilight/bake.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/seams.hpp"

#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace hemilight;

namespace {

using test::uv_mesh;

constexpr int size = 32;

glm::vec2 uv(float x, float y) { return glm::vec2(x, y) / float(size); }

// A floor (y = 0, facing +y) of two unit quads side by side, x in [0, 1] and [1, 2], z in [0, 1],
// cut at x = 1 into two charts of a 32 x 32 lightmap: A at u in [2, 14] texels, B at u in
// [17.3, 28.9] (texel centres of the two sides at other distances from the cut), v in [2, 30];
// under a sky of 1.
void two_chart_floor(uv_mesh& m, const material& mat = material{glm::vec3(0.0f), glm::vec3(0.5f), false}) {
  m.sky = glm::vec3(1.0f);
  m.quad({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}, uv(2, 2), uv(14, 2), uv(14, 30), uv(2, 30), mat);
  m.quad({1, 0, 1}, {2, 0, 1}, {2, 0, 0}, {1, 0, 0}, uv(17.3f, 2), uv(28.9f, 2), uv(28.9f, 30), uv(17.3f, 30), mat);
}

// A black two-sided wall across the floor at x = wall_x, 0.5 high (no texels: UVs of zero area).
void wall(uv_mesh& m, float wall_x, float height = 0.5f) {
  const material black{glm::vec3(0.0f), glm::vec3(0.0f), true};
  m.quad({wall_x, 0, -0.5f}, {wall_x, 0, 1.5f}, {wall_x, height, 1.5f}, {wall_x, height, -0.5f}, uv(0, 0), uv(0, 0), uv(0, 0),
         uv(0, 0), black);
}

// A bake_result whose irradiance is `value` in every texel of the rectangle [x0, x1) x [0, size)
// (texel columns), 0 elsewhere, all marked sampled.
void fill_columns(bake_result& r, int x0, int x1, float value) {
  if (r.irradiance.width == 0) {
    r.irradiance = image::make(size, size, 3);
    r.sampled.assign(std::size_t(size) * size, 1);
  }
  for (int y = 0; y < size; ++y)
    for (int x = x0; x < x1; ++x)
      for (int c = 0; c < 3; ++c) r.irradiance.pixels[(std::size_t(y) * size + std::size_t(x)) * 3 + std::size_t(c)] = value;
}

// The relative RMS difference of two images' luminance over the texels where mask is 1 (and the
// reference is not 0).
double rms_relative(const image& a, const image& ref, const std::vector<std::uint8_t>& mask) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < mask.size(); ++k) {
    if (!mask[k]) continue;
    const float* p = a.pixels.data() + 3 * k;
    const float* q = ref.pixels.data() + 3 * k;
    const double ya = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2], yr = 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
    if (yr <= 0.0) continue;
    sum += (ya - yr) * (ya - yr) / (yr * yr);
    ++n;
  }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

// The two-chart floor with a black wall across it at x = wall_x (1: on the cut).
uv_mesh floor_and_wall(float wall_x) {
  uv_mesh m;
  two_chart_floor(m);
  wall(m, wall_x);
  return m;
}

// A bake with stitching off and one with it on, the rest as `o`.
struct raw_and_stitched {
  bake_result raw, stitched;
};
raw_and_stitched bake_both(const bake_input& in, bake_options o) {
  raw_and_stitched r;
  o.stitch_seams = false;
  r.raw = bake_lightmap(in, o);
  o.stitch_seams = true;
  r.stitched = bake_lightmap(in, o);
  return r;
}

bake_options small_options() {
  bake_options o;
  o.width = o.height = size;
  o.sampler.resolution = 64;
  o.bounces = 1;
  return o;
}

}  // namespace

TEST_CASE("measure_seams: two charts of constant values give the step in closed form", "[seams]") {
  uv_mesh m;
  two_chart_floor(m);
  bake_result r;
  fill_columns(r, 0, 16, 1.0f);
  fill_columns(r, 16, size, 1.1f);
  const seam_report s = measure_seams(m.input(), r);
  // One piece: the edge x = 1 of one triangle of each quad; its UV length is 28 texels on both
  // sides. Every lookup reads 1 on A's side and 1.1 on B's (the footprints stay in each chart's
  // constant columns): relative step 0.1 / 1.05 everywhere.
  CHECK(s.coplanar.pieces == 1);
  CHECK(s.crease.pieces == 0);
  CHECK(s.walled.pieces == 0);
  CHECK(s.coplanar.length_texels == Approx(28.0).epsilon(1e-6));
  const double step = 0.1 / 1.05;
  CHECK(s.coplanar.rms == Approx(step).epsilon(1e-5));  // float lookups: ~1e-7 relative
  CHECK(s.coplanar.p95 == Approx(step).epsilon(1e-5));
  CHECK(s.coplanar.max == Approx(step).epsilon(1e-5));
  CHECK(s.coplanar.step_fraction == 1.0);
  CHECK(s.coplanar.samples == std::size_t(4 * 28));  // samples_per_texel 4
  // Equal values: no step.
  bake_result flat;
  fill_columns(flat, 0, size, 0.7f);
  CHECK(measure_seams(m.input(), flat).coplanar.max == 0.0);
}

TEST_CASE("find_seams: one chart has no seam; T-junctions, creases and walls are told apart", "[seams]") {
  bake_result r;
  fill_columns(r, 0, size, 1.0f);
  SECTION("one chart across the edge") {
    uv_mesh m;
    m.quad({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}, uv(2, 2), uv(14, 2), uv(14, 30), uv(2, 30));
    m.quad({1, 0, 1}, {2, 0, 1}, {2, 0, 0}, {1, 0, 0}, uv(14, 2), uv(26, 2), uv(26, 30), uv(14, 30));
    const seam_report s = measure_seams(m.input(), r);
    CHECK(s.coplanar.pieces + s.crease.pieces + s.walled.pieces == 0);
  }
  SECTION("a T-junction: B's edge split in two at z = 0.5") {
    uv_mesh m;
    m.quad({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}, uv(2, 2), uv(14, 2), uv(14, 30), uv(2, 30));
    m.quad({1, 0, 1}, {2, 0, 1}, {2, 0, 0.5f}, {1, 0, 0.5f}, uv(17, 2), uv(29, 2), uv(29, 16), uv(17, 16));
    m.quad({1, 0, 0.5f}, {2, 0, 0.5f}, {2, 0, 0}, {1, 0, 0}, uv(17, 16), uv(29, 16), uv(29, 30), uv(17, 30));
    const seam_report s = measure_seams(m.input(), r);
    CHECK(s.coplanar.pieces == 2);  // A's one edge against each half of B's
    CHECK(s.coplanar.length_texels == Approx(28.0).epsilon(1e-6));
  }
  SECTION("a crease: B stands up as a wall") {
    uv_mesh m;
    m.quad({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}, uv(2, 2), uv(14, 2), uv(14, 30), uv(2, 30));
    m.quad({1, 0, 1}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}, uv(17, 2), uv(17, 30), uv(29, 30), uv(29, 2));
    const seam_report s = measure_seams(m.input(), r);
    CHECK(s.coplanar.pieces == 0);
    CHECK(s.crease.pieces == 1);
  }
  SECTION("a wall standing on the seam, and one beside it") {
    const uv_mesh on = floor_and_wall(1.0f), beside = floor_and_wall(1.2f);
    const seam_report s_on = measure_seams(on.input(), r), s_beside = measure_seams(beside.input(), r);
    CHECK(s_on.walled.pieces == 1);
    CHECK(s_on.coplanar.pieces == 0);
    CHECK(s_beside.walled.pieces == 0);
    CHECK(s_beside.coplanar.pieces == 1);
  }
}

TEST_CASE("Stitching removes the step along a seam and leaves the rest of the lightmap as baked", "[seams][bake]") {
  // The two-chart floor with a black wall 0.6 beyond the cut: the irradiance falls towards the
  // wall, so the two sides' texel centres (at other distances from the cut) differ.
  const uv_mesh m = floor_and_wall(1.6f);
  const bake_input in = m.input();
  bake_options o = small_options();
  const raw_and_stitched both = bake_both(in, o);
  const bake_result &raw = both.raw, &stitched = both.stitched;
  // The converged reference: a hemicube at every texel, N = 256, unstitched.
  bake_options ro = small_options();
  ro.use_cache = false;
  ro.sampler.resolution = 256;
  ro.stitch_seams = false;
  const bake_result reference = bake_lightmap(in, ro);

  const seam_report before = measure_seams(in, raw), after = measure_seams(in, stitched), converged = measure_seams(in, reference);
  const double bake_error = rms_relative(raw.irradiance, reference.irradiance, raw.valid);
  INFO("seam RMS before " << before.coplanar.rms << ", after " << after.coplanar.rms << ", converged " << converged.coplanar.rms
                          << "; bake error " << bake_error);
  REQUIRE(before.coplanar.pieces == 1);
  // The step is there before (a better bake does not remove it: the converged map has it too).
  CHECK(before.coplanar.rms > 0.01);
  CHECK(converged.coplanar.rms > 0.01);
  // After: at most the bake's own error against converged (the target), and a tenth of before.
  CHECK(after.coplanar.rms <= bake_error);
  CHECK(after.coplanar.rms <= 0.1 * before.coplanar.rms);
  CHECK(stitched.stats.seam_texels > 0);
  CHECK(stitched.stats.stitch_seconds > 0.0);
  CHECK(raw.stats.seam_texels == 0);

  // Texels that no seam lookup reads are bitwise as baked; the sampled texels change by at most
  // 0.5% RMS (the target), and stitching does not move the map away from the converged one.
  std::vector<std::uint8_t> footprint(raw.sampled.size(), 0);
  std::size_t changed = 0;
  for (std::size_t k = 0; k < footprint.size(); ++k)
    if (std::memcmp(&raw.irradiance.pixels[3 * k], &stitched.irradiance.pixels[3 * k], 3 * sizeof(float)) != 0) {
      footprint[k] = 1;
      ++changed;
    }
  CHECK(changed <= stitched.stats.seam_texels + 2 * std::size_t(stitched.stats.dilated_texels));
  // Changed texels lie in the columns next to the cut (A's 13..15, B's 16..18) or are dilated
  // from them: nothing else moves.
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (raw.sampled[std::size_t(y) * size + std::size_t(x)] && footprint[std::size_t(y) * size + std::size_t(x)]) {
        INFO("texel " << x << ", " << y);
        CHECK((x >= 12 && x <= 18));
      }
  CHECK(rms_relative(stitched.irradiance, raw.irradiance, raw.sampled) <= 0.005);
  // Against converged, texel by texel: stitching moves the texels beside the cut off their point
  // values (so that lookups on the cut agree), here 6 of the 24 sampled columns; the error grows
  // by less than half (measured: 0.0050 -> 0.0061).
  CHECK(rms_relative(stitched.irradiance, reference.irradiance, raw.valid) <= 1.5 * bake_error);
}

TEST_CASE("Stitching joins charts on different pages of a scene bake", "[seams][bake]") {
  // The two-chart floor as two meshes, A on page 0 and B on page 1 (each chart moved to u in
  // [2, 14] / [17.3, 28.9] of its own page), with the wall beside the cut.
  const uv_mesh m = floor_and_wall(1.6f);
  scene_bake_input in;
  in.geometry = m.input();
  in.pages = {lightmap_page{}, lightmap_page{}};
  for (lightmap_page& p : in.pages) p.width = p.height = size;
  in.meshes = {bake_mesh{0, 2, 0, glm::vec2(1.0f), glm::vec2(0.0f)}, bake_mesh{2, 2, 1, glm::vec2(1.0f), glm::vec2(0.0f)},
               bake_mesh{4, 2, -1, glm::vec2(1.0f), glm::vec2(0.0f)}};
  bake_options o = small_options();
  o.stitch_seams = false;
  const scene_bake_result raw = bake_scene(in, o);
  o.stitch_seams = true;
  const scene_bake_result stitched = bake_scene(in, o);
  const seam_report before = measure_seams(in, raw), after = measure_seams(in, stitched);
  INFO("seam RMS before " << before.coplanar.rms << ", after " << after.coplanar.rms);
  REQUIRE(before.coplanar.pieces == 1);
  CHECK(before.coplanar.rms > 0.01);
  CHECK(after.coplanar.rms <= 0.1 * before.coplanar.rms);
  CHECK(stitched.stats.seam_texels > 0);
  for (std::size_t p = 0; p < 2; ++p) CHECK(rms_relative(stitched.pages[p].irradiance, raw.pages[p].irradiance, raw.pages[p].sampled) <= 0.005);
}

TEST_CASE("Stitching covers the directional maps and the shadow mask", "[seams][bake]") {
  // A soft sun over the wall: the penumbra of the wall's top (x from about 0.93 to 1.17) and the
  // sky's gradient straddle the cut.
  const uv_mesh m = floor_and_wall(1.6f);
  const bake_input in = m.input();
  bake_options o = small_options();
  o.output_sh_l1 = true;
  o.output_hl2 = true;
  light sun;
  sun.type = light_type::directional;
  sun.direction = glm::vec3(-1.0f, -0.9f, 0.2f);
  sun.color = glm::vec3(3.0f);
  sun.radius = 0.2f;
  o.lights = {sun};
  o.shadow_mask_lights = {0, -1, -1, -1};
  const raw_and_stitched both = bake_both(in, o);
  const bake_result &raw = both.raw, &stitched = both.stitched;
  // Each map seen as an irradiance image (a scalar per texel in all three channels) and measured
  // along the seam: the step falls to a tenth or less.
  const auto as_rgb = [](const image& img, int channel) {
    image out = image::make(img.width, img.height, 3);
    for (std::size_t k = 0; k < std::size_t(img.width) * std::size_t(img.height); ++k)
      for (int c = 0; c < 3; ++c) out.pixels[3 * k + std::size_t(c)] = img.pixels[k * std::size_t(img.channels) + std::size_t(channel)];
    return out;
  };
  const auto step_of = [&](const bake_result& r, const image& img, int channel) {
    bake_result view;
    view.irradiance = as_rgb(img, channel);
    view.sampled = r.sampled;
    return measure_seams(in, view).coplanar.rms;
  };
  // Each map's step falls to a tenth, or below 1% where it was small (a third of the HL2 basis
  // faces away from the sun and the wall); the step was there before on every map but that one.
  double hl2_largest = 0.0;
  const auto check_map = [&](const char* name, const image& a, const image& b, int channel) {
    const double before = step_of(raw, a, channel), after = step_of(stitched, b, channel);
    INFO(name << ": seam RMS before " << before << ", after " << after);
    CHECK(after <= std::max(0.1 * before, 0.01));
    return before;
  };
  CHECK(check_map("irradiance", raw.irradiance, stitched.irradiance, 1) > 0.02);
  CHECK(check_map("sh_l1[0]", raw.sh_l1[0], stitched.sh_l1[0], 1) > 0.02);
  for (int k = 0; k < 3; ++k) hl2_largest = std::max(hl2_largest, check_map("hl2", raw.hl2[std::size_t(k)], stitched.hl2[std::size_t(k)], 1));
  CHECK(hl2_largest > 0.02);
  CHECK(check_map("shadow mask", raw.shadow_mask, stitched.shadow_mask, 0) > 0.02);
  // The mask stays a visibility.
  for (float v : stitched.shadow_mask.pixels) CHECK((v >= 0.0f && v <= 1.0f));
}

TEST_CASE("A hard shadow edge along a seam is kept, not blurred", "[seams][bake]") {
  // A black roof over chart A exactly (x in [0, 1], 0.5 up) and a hard sun straight down, no sky:
  // A is 0 and B is 2 up to the cut (closed form). Each side is flat, so the step is no sampling
  // step: stitching leaves both sides as baked.
  uv_mesh m;
  two_chart_floor(m);
  const material black{glm::vec3(0.0f), glm::vec3(0.0f), true};
  m.quad({0, 0.5f, 0}, {1, 0.5f, 0}, {1, 0.5f, 1}, {0, 0.5f, 1}, uv(0, 0), uv(0, 0), uv(0, 0), uv(0, 0), black);
  m.sky = glm::vec3(0.0f);
  const bake_input in = m.input();
  bake_options o = small_options();
  light sun;
  sun.type = light_type::directional;
  sun.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  sun.color = glm::vec3(2.0f);
  o.lights = {sun};
  const raw_and_stitched both = bake_both(in, o);
  const bake_result &raw = both.raw, &stitched = both.stitched;
  CHECK(stitched.stats.seam_texels == 0);
  CHECK(std::memcmp(raw.irradiance.pixels.data(), stitched.irradiance.pixels.data(), raw.irradiance.pixels.size() * sizeof(float)) == 0);
  const seam_report s = measure_seams(in, stitched);
  CHECK(s.coplanar.pieces == 1);
  CHECK(s.coplanar.rms == Approx(2.0 / 1.0).epsilon(1e-6));  // |0 - 2| / mean 1
}

TEST_CASE("A seam under a wall is not stitched", "[seams][bake]") {
  // The wall stands on the cut: its two sides see different halves of the sky, and stitching
  // them together would carry light under the wall (a leak).
  const uv_mesh m = floor_and_wall(1.0f);
  const bake_input in = m.input();
  bake_options o = small_options();
  const raw_and_stitched both = bake_both(in, o);
  const bake_result &raw = both.raw, &stitched = both.stitched;
  CHECK(stitched.stats.seam_texels == 0);
  CHECK(std::memcmp(raw.irradiance.pixels.data(), stitched.irradiance.pixels.data(), raw.irradiance.pixels.size() * sizeof(float)) == 0);
  CHECK(measure_seams(in, stitched).walled.pieces == 1);
}

TEST_CASE("measure_seams rejects bad options and results that do not match the input", "[seams]") {
  uv_mesh m;
  two_chart_floor(m);
  bake_result r;
  fill_columns(r, 0, size, 1.0f);
  const auto fails_with = [&](const seam_options& o, const bake_result& res, const std::string& what) {
    try {
      measure_seams(m.input(), res, o);
      FAIL("no error for " << what);
    } catch (const error& e) {
      CHECK(e.code() == status::invalid_argument);
      CHECK_THAT(e.what(), Catch::Contains(what));
    }
  };
  seam_options o;
  o.coplanar_degrees = 0.0f;
  fails_with(o, r, "coplanar_degrees");
  o = seam_options{};
  o.samples_per_texel = std::nanf("");
  fails_with(o, r, "samples_per_texel");
  o = seam_options{};
  o.step_threshold = -1.0f;
  fails_with(o, r, "step_threshold");
  bake_result short_sampled = r;
  short_sampled.sampled.pop_back();
  fails_with(seam_options{}, short_sampled, "result.sampled");
  bake_result grey = r;
  grey.irradiance = image::make(size, size, 4);
  fails_with(seam_options{}, grey, "result.irradiance");
  uv_mesh far = m;
  far.uvs[0].x = 1.5f;
  try {
    measure_seams(far.input(), r);
    FAIL("no error for a UV outside [0, 1]");
  } catch (const error& e) {
    CHECK_THAT(e.what(), Catch::Contains("lightmap_uvs[0].u = 1.5"));
  }
  // A huge triangle among small ones (edges 1e15 times the cells of the T-junction search): the
  // search stays bounded and finds the one seam.
  uv_mesh huge = m;
  huge.add({-1e15f, 0, -1e15f}, {1e15f, 0, -1e15f}, {0, 1e15f, -1e15f}, uv(0.5f, 0.5f), uv(1.5f, 0.5f), uv(0.5f, 1.5f));
  CHECK(measure_seams(huge.input(), r).coplanar.pieces == 1);
  uv_mesh bad = m;
  bad.indices[4] = 99;
  try {
    measure_seams(bad.input(), r);
    FAIL("no error for an index out of range");
  } catch (const error& e) {
    CHECK_THAT(e.what(), Catch::Contains("indices[4]"));
  }
}
