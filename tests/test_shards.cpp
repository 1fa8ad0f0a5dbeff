// Tests of shards.hpp: the sharded scene bake against bake_scene (bitwise with one shard, and with
// any number of shards without the cache), determinism of the jobs (order, threads, each job run
// alone with its inputs copied as a file would carry them), the S-shard bake's error against a
// hemicube at every texel, and the refusals of mismatched inputs.
#include "hemilight/reference_scenes.hpp"
#include "hemilight/shards.hpp"

#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace hemilight;

namespace {

// A scene bake of one page from a reference scene with generated lightmap UVs (arrays owned).
struct one_page_scene {
  scene_mesh mesh;
  std::vector<light> lights;
  scene_bake_input input;

  one_page_scene(const lit_scene& s, int size, glm::vec3 sky) : mesh(s.mesh), lights(s.lights) {
    generate_lightmap_uvs(mesh, size, 2);
    input.geometry.scene = mesh.desc();
    input.geometry.scene.sky_radiance = sky;
    lightmap_page page;
    page.width = page.height = size;
    input.pages.push_back(page);
    bake_mesh all;
    all.triangle_count = mesh.triangle_count();
    all.page = 0;
    input.meshes.push_back(all);
  }
};

bake_options small_options(const std::vector<light>& lights) {
  bake_options o;
  o.sampler.resolution = 24;
  o.bounces = 2;
  o.thread_count = 2;
  o.lights = lights;
  return o;
}

// Every image of two scene bakes bitwise equal (and the per-texel arrays).
void require_same_bits(const scene_bake_result& a, const scene_bake_result& b) {
  REQUIRE(a.pages.size() == b.pages.size());
  const auto same = [](const image& x, const image& y) {
    REQUIRE(x.width == y.width);
    REQUIRE(x.height == y.height);
    REQUIRE(x.channels == y.channels);
    REQUIRE(x.pixels.size() == y.pixels.size());
    if (!x.pixels.empty()) CHECK(std::memcmp(x.pixels.data(), y.pixels.data(), x.pixels.size() * sizeof(float)) == 0);
  };
  for (std::size_t p = 0; p < a.pages.size(); ++p) {
    const bake_result &x = a.pages[p], &y = b.pages[p];
    same(x.irradiance, y.irradiance);
    for (std::size_t c = 0; c < 4; ++c) same(x.sh_l1[c], y.sh_l1[c]);
    for (std::size_t c = 0; c < 3; ++c) same(x.hl2[c], y.hl2[c]);
    same(x.shadow_mask, y.shadow_mask);
    same(x.ao, y.ao);
    CHECK(x.valid == y.valid);
    CHECK(x.sampled == y.sampled);
    CHECK(x.coverage == y.coverage);
  }
}

// Relative RMS of a's irradiance against ref's over ref's valid texels (luminance).
double relative_rms(const bake_result& a, const bake_result& ref) {
  double se = 0.0, sr = 0.0;
  for (std::size_t k = 0; k < ref.valid.size(); ++k) {
    if (!ref.valid[k]) continue;
    const auto lum = [k](const image& img) {
      return 0.2126 * img.pixels[3 * k] + 0.7152 * img.pixels[3 * k + 1] + 0.0722 * img.pixels[3 * k + 2];
    };
    const double d = lum(a.irradiance) - lum(ref.irradiance);
    se += d * d;
    sr += lum(ref.irradiance) * lum(ref.irradiance);
  }
  return std::sqrt(se / std::max(sr, 1e-30));
}

// The sharded bake run job by job through the public functions, each job's inputs copied (as
// files would carry them), the shards of each pass run in reverse order.
scene_bake_result bake_job_by_job(const scene_bake_input& in, const bake_options& o, int shards) {
  std::vector<bake_shard_result> first, current;
  bake_pass_state state;
  for (int pass = 1;; ++pass) {
    current.assign(std::size_t(shards), bake_shard_result{});
    for (int s = shards - 1; s >= 0; --s) {
      const bake_pass_state copy = state;
      current[std::size_t(s)] = bake_scene_shard(in, o, s, shards, pass, pass > 1 ? &copy : nullptr);
    }
    std::reverse(current.begin(), current.end());  // merges take the shards in any order
    if (pass == 1) first = current;
    if (pass == o.bounces) return finish_sharded_bake(in, o, current.data(), current.size(), first.data(), pass > 1 ? &state : nullptr);
    state = merge_bake_pass(in, o, pass, current.data(), current.size(), first.data(), pass > 1 ? &state : nullptr);
  }
}

}  // namespace

TEST_CASE("Sharded bake: one shard gives bake_scene's bits, with every output", "[shards]") {
  one_page_scene sc(hexagon_room_sunlit(2), 40, glm::vec3(1.0f));
  bake_options o = small_options(sc.lights);
  o.output_sh_l1 = true;
  o.output_hl2 = true;
  o.ao_distance = 0.5f;
  o.shadow_mask_lights = {{0, -1, -1, -1}};
  SECTION("two bounces") {}
  SECTION("one bounce, indirect only") {
    o.bounces = 1;
    o.indirect_only = true;
  }
  SECTION("three bounces, indirect only") {
    o.bounces = 3;
    o.indirect_only = true;
  }
  const scene_bake_result ref = bake_scene(sc.input, o);
  const scene_bake_result sharded = bake_scene_sharded(sc.input, o, 1);
  require_same_bits(sharded, ref);
  CHECK(sharded.stats.hemicubes == ref.stats.hemicubes);
  CHECK(sharded.stats.passes.size() == ref.stats.passes.size());
}

TEST_CASE("Sharded bake: without the cache any shard count gives bake_scene's bits", "[shards]") {
  one_page_scene sc({cornell_box(), {}}, 32, glm::vec3(0.0f));
  bake_options o = small_options({});
  o.use_cache = false;
  o.ao_distance = 0.2f;
  const scene_bake_result ref = bake_scene(sc.input, o);
  for (int shards : {2, 3, 7}) {
    INFO(shards << " shards");
    require_same_bits(bake_scene_sharded(sc.input, o, shards), ref);
  }
  // More shards than samples: the empty shards are jobs like the others.
  require_same_bits(bake_scene_sharded(sc.input, o, 4096), ref);
}

TEST_CASE("Sharded bake: jobs run alone, in any order and with any threads give the same bits", "[shards]") {
  one_page_scene sc(hexagon_room_sunlit(2), 40, glm::vec3(1.0f));
  bake_options o = small_options(sc.lights);
  o.output_sh_l1 = true;
  o.ao_distance = 0.5f;
  const scene_bake_result one_process = bake_scene_sharded(sc.input, o, 3);
  bake_options other = o;
  other.thread_count = 1;
  require_same_bits(bake_job_by_job(sc.input, other, 3), one_process);
  // The key ignores the thread count: it does not change bits.
  CHECK(bake_key(sc.input, o) == bake_key(sc.input, other));
}

TEST_CASE("Sharded bake: the cache's error with shards stays that of the bake", "[shards]") {
  // Reference: a hemicube at every texel. The bake's own error (one shard, i.e. bake_scene) and
  // the sharded bakes' against it: shards lose records at their borders, so their error may grow
  // a little; bounded at 1.5x the bake's own plus 0.5% (measured: docs/distributed.md).
  one_page_scene sc(hexagon_room_sunlit(2), 48, glm::vec3(1.0f));
  bake_options o = small_options(sc.lights);
  bake_options reference = o;
  reference.use_cache = false;
  const scene_bake_result ref = bake_scene(sc.input, reference);
  const double own = relative_rms(bake_scene(sc.input, o).pages[0], ref.pages[0]);
  for (int shards : {2, 4, 8}) {
    const scene_bake_result r = bake_scene_sharded(sc.input, o, shards);
    const double e = relative_rms(r.pages[0], ref.pages[0]);
    INFO(shards << " shards: " << e << " against the bake's own " << own);
    CHECK(e <= 1.5 * own + 0.005);
  }
}

TEST_CASE("Sharded bake: mismatched inputs are refused, naming what differs", "[shards]") {
  one_page_scene sc({cornell_box(), {}}, 24, glm::vec3(0.0f));
  bake_options o = small_options({});
  o.bounces = 3;
  std::vector<bake_shard_result> pass1;
  for (int s = 0; s < 2; ++s) pass1.push_back(bake_scene_shard(sc.input, o, s, 2, 1, nullptr));
  const bake_pass_state state = merge_bake_pass(sc.input, o, 1, pass1.data(), 2, pass1.data(), nullptr);

  using test::require_error;
  const status bad = status::invalid_argument;
  require_error([&] { bake_scene_shard(sc.input, o, 2, 2, 1, nullptr); }, bad, "bake_scene_shard: shard = 2 is not in [0, 2)");
  require_error([&] { bake_scene_shard(sc.input, o, 0, 0, 1, nullptr); }, bad, "shard_count = 0 is not in [1, 4096]");
  require_error([&] { bake_scene_shard(sc.input, o, 0, 2, 4, nullptr); }, bad, "pass = 4 is not in [1, 3]");
  require_error([&] { bake_scene_shard(sc.input, o, 0, 2, 2, nullptr); }, bad, "pass 2 needs the state after pass 1");
  require_error([&] { bake_scene_shard(sc.input, o, 0, 2, 3, &state); }, bad, "the previous state follows pass 1, not pass 2");
  require_error([&] { bake_scene_shard(sc.input, o, 0, 3, 2, &state); }, bad, "comes from 2 shards, this bake has 3");
  bake_options other = o;
  other.sampler.resolution = 32;
  require_error([&] { bake_scene_shard(sc.input, other, 0, 2, 2, &state); }, bad, "made by another bake");
  require_error([&] { merge_bake_pass(sc.input, other, 1, pass1.data(), 2, pass1.data(), nullptr); }, bad,
                "merge_bake_pass: shards[0] (shard 0 of pass 1) was baked from another scene or options");
  // A shard missing (the same one twice), or too few.
  std::vector<bake_shard_result> twice = {pass1[0], pass1[0]};
  require_error([&] { merge_bake_pass(sc.input, o, 1, twice.data(), 2, twice.data(), nullptr); }, bad, "shards[1] is shard 0 again");
  require_error([&] { merge_bake_pass(sc.input, o, 1, pass1.data(), 1, pass1.data(), nullptr); }, bad,
                "shards[0] is shard 0 of 2, not one of 1");
  // A shard whose values were cut short.
  std::vector<bake_shard_result> cut = pass1;
  cut[1].values.pop_back();
  require_error([&] { merge_bake_pass(sc.input, o, 1, cut.data(), 2, cut.data(), nullptr); }, bad, "shards[1] (shard 1) holds");
  // The last pass through merge_bake_pass, an early one through finish_sharded_bake.
  require_error([&] { merge_bake_pass(sc.input, o, 3, pass1.data(), 2, pass1.data(), &state); }, bad,
                "pass = 3 is not in [1, 2] (the bake has 3 bounces; the last pass is finish_sharded_bake's)");
  require_error([&] { merge_bake_pass(sc.input, o, 1, pass1.data(), 5000, pass1.data(), nullptr); }, bad,
                "merge_bake_pass: shard_count = 5000 is not in [1, 4096]");
  std::vector<bake_shard_result> pass2;
  for (int s = 0; s < 2; ++s) pass2.push_back(bake_scene_shard(sc.input, o, s, 2, 2, &state));
  const bake_pass_state state2 = merge_bake_pass(sc.input, o, 2, pass2.data(), 2, pass1.data(), &state);
  require_error([&] { finish_sharded_bake(sc.input, o, pass1.data(), 2, pass1.data(), &state2); }, bad,
                "shards[0] is a result of pass 1, not pass 3");
  require_error([&] { finish_sharded_bake(sc.input, o, pass2.data(), 2, pass1.data(), &state); }, bad,
                "the previous state follows pass 1, not pass 2");
  // Another scene: the key differs.
  scene_bake_input moved = sc.input;
  std::vector<glm::vec3> positions(sc.mesh.positions);
  positions[0].x += 1e-3f;
  moved.geometry.scene.positions = positions.data();
  CHECK(bake_key(moved, o) != bake_key(sc.input, o));
  require_error([&] { bake_scene_shard(moved, o, 0, 2, 2, &state); }, bad, "made by another bake");
}
