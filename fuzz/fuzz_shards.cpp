// libFuzzer harness: the sharded scene bake's plain-data entries with crafted shards and states,
// as a program receiving them from another machine would get them. A fixed scene (two quads on
// one 8 x 8 page, sky, N = 8, two bounces) and its real pass-1 shards (S = 2); from the bytes, a
// shard (hemilight_bake_shard_create: its numbers, channel names and values, some real, some
// not) replaces one of them in hemilight_merge_bake_pass / hemilight_finish_sharded_bake, and a
// state (hemilight_bake_pass_state_create) feeds a pass-2 job and the finish. Checks the contract:
// no crash, finite outputs on OK, the page's buffers untouched on failure.
#include "fuzz_input.hpp"

#include <string>

namespace {

constexpr int size = 8, texels = size * size;
const float floor_positions[] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
const float wall_positions[] = {0, 0, -1, 1, 0, -1, 1, 1, -1, 0, 1, -1};
const float uvs[2][8] = {{0.05f, 0.05f, 0.45f, 0.05f, 0.45f, 0.95f, 0.05f, 0.95f},
                         {0.55f, 0.05f, 0.95f, 0.05f, 0.95f, 0.95f, 0.55f, 0.95f}};
const std::uint32_t quad[] = {0, 1, 2, 0, 2, 3};

struct fixture {
  hemilight_bake_mesh meshes[2];
  hemilight_bake_placement placements[2];
  hemilight_bake_page page;
  hemilight_bake_scene_desc scene;
  hemilight_bake_options options;
  float irradiance[3 * texels];
  hemilight_bake_shard* pass1[2] = {nullptr, nullptr};
  hemilight_bake_pass_state* state = nullptr;

  fixture() {
    std::memset(meshes, 0, sizeof meshes);
    std::memset(placements, 0, sizeof placements);
    std::memset(&page, 0, sizeof page);
    const float* positions[2] = {floor_positions, wall_positions};
    for (int m = 0; m < 2; ++m) {
      meshes[m].positions = positions[m];
      meshes[m].lightmap_uvs = uvs[m];
      meshes[m].vertex_count = 4;
      meshes[m].indices = quad;
      meshes[m].triangle_count = 2;
      for (float& a : meshes[m].material.albedo) a = 0.6f;
      placements[m].uv_scale[0] = placements[m].uv_scale[1] = 1.0f;
    }
    page.width = page.height = size;
    page.irradiance_rgb = irradiance;
    page.irradiance_capacity = 3 * texels;
    hemilight_bake_scene_desc_init(&scene);
    scene.meshes = meshes;
    scene.mesh_count = 2;
    scene.placements = placements;
    scene.pages = &page;
    scene.page_count = 1;
    hemilight_bake_options_init(&options);
    options.resolution = 8;
    options.bounces = 2;
    options.thread_count = 1;
    for (float& s : options.sky_radiance) s = 1.0f;
    for (int s = 0; s < 2; ++s)
      if (hemilight_bake_scene_shard(&scene, &options, s, 2, 1, nullptr, &pass1[s]) != HEMILIGHT_OK) fuzz::violated("fixture shard");
    const hemilight_bake_shard* const shards[2] = {pass1[0], pass1[1]};
    if (hemilight_merge_bake_pass(&scene, &options, 1, shards, 2, shards, nullptr, &state) != HEMILIGHT_OK) fuzz::violated("fixture state");
  }
};

// A shard from the bytes: one of the real ones with some numbers, names or values changed.
hemilight_bake_shard* crafted_shard(fuzz::input& in, const fixture& f) {
  const hemilight_bake_shard* base = f.pass1[in.small(0, 1)];
  hemilight_bake_shard_info info;
  hemilight_bake_shard_info_init(&info);
  if (hemilight_bake_shard_get(base, &info, nullptr, 0) != HEMILIGHT_OK) fuzz::violated("shard_get");
  std::vector<float> values(info.sample_count * info.channel_count);
  if (hemilight_bake_shard_get(base, &info, values.data(), values.size()) != HEMILIGHT_OK) fuzz::violated("shard_get values");
  std::vector<std::string> names;
  for (std::size_t c = 0; c < info.channel_count; ++c) names.push_back(hemilight_bake_shard_channel_name(base, c));
  switch (in.small(0, 7)) {
    case 0: info.key ^= std::uint64_t(in.u32()) << in.small(0, 32); break;
    case 1: info.pass = in.small(-2, 70); break;
    case 2: info.shard = in.small(-2, 4); info.shard_count = in.small(-1, 5); break;
    case 3: info.sample_count = std::size_t(in.small(0, 40)); break;
    case 4: info.channel_count = std::size_t(in.small(0, 8)); break;
    case 5: if (!names.empty()) names[std::size_t(in.small(0, 255)) % names.size()] = in.small(0, 1) ? "E.R" : "x"; break;
    default: break;
  }
  const std::size_t changed = std::size_t(in.small(0, 8));
  for (std::size_t k = 0; k < changed && !values.empty(); ++k) values[std::size_t(in.u32()) % values.size()] = in.any_float(4.0f);
  if (in.small(0, 7) == 0 && !values.empty()) values.pop_back();
  if (names.size() < info.channel_count) names.resize(info.channel_count, "E.G");
  std::vector<const char*> name_ptrs;
  for (const std::string& n : names) name_ptrs.push_back(n.c_str());
  hemilight_bake_shard* out = nullptr;
  if (hemilight_bake_shard_create(&info, name_ptrs.data(), values.data(), values.size(), &out) != HEMILIGHT_OK && out)
    fuzz::violated("shard_create wrote *out on failure");
  return out;
}

// A state from the bytes: the real one with some numbers or texels changed.
hemilight_bake_pass_state* crafted_state(fuzz::input& in, const fixture& f) {
  hemilight_bake_pass_state_info info;
  hemilight_bake_pass_state_info_init(&info);
  if (hemilight_bake_pass_state_get(f.state, &info, nullptr, 0, nullptr, nullptr, nullptr, nullptr, 0) != HEMILIGHT_OK)
    fuzz::violated("state_get");
  std::vector<float> rgba(4 * std::size_t(info.width) * std::size_t(info.height));
  std::size_t hemicubes[1], records[1], invalid[1];
  double seconds[1];
  if (hemilight_bake_pass_state_get(f.state, &info, rgba.data(), rgba.size(), hemicubes, records, invalid, seconds, 1) != HEMILIGHT_OK)
    fuzz::violated("state_get values");
  switch (in.small(0, 5)) {
    case 0: info.key ^= std::uint64_t(in.u32()) << in.small(0, 32); break;
    case 1: info.pass = in.small(-1, 66); break;
    case 2: info.width = in.small(-1, 12); break;
    case 3: info.height = in.small(-1, 40); break;
    case 4: info.pass_count = std::size_t(in.small(0, 70)); break;
    default: break;
  }
  const std::size_t changed = std::size_t(in.small(0, 8));
  for (std::size_t k = 0; k < changed && !rgba.empty(); ++k) rgba[std::size_t(in.u32()) % rgba.size()] = in.any_float(2.0f);
  hemilight_bake_pass_state* out = nullptr;
  if (hemilight_bake_pass_state_create(&info, rgba.data(), rgba.size(), info.pass_count <= 1 ? hemicubes : nullptr,
                                       info.pass_count <= 1 ? records : nullptr, info.pass_count <= 1 ? invalid : nullptr,
                                       info.pass_count <= 1 ? seconds : nullptr, &out) != HEMILIGHT_OK &&
      out)
    fuzz::violated("pass_state_create wrote *out on failure");
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size_in) {
  static fixture f;
  fuzz::input in(data, size_in);
  hemilight_bake_shard* shard = crafted_shard(in, f);
  hemilight_bake_pass_state* state = crafted_state(in, f);
  const int slot = in.small(0, 1);
  const hemilight_bake_shard* shards[2] = {f.pass1[0], f.pass1[1]};
  if (shard) shards[slot] = shard;
  // A merge of pass 1 with the crafted shard.
  hemilight_bake_pass_state* merged = nullptr;
  const hemilight_status sm = hemilight_merge_bake_pass(&f.scene, &f.options, 1, shards, 2, shards, nullptr, &merged);
  if (sm != HEMILIGHT_OK && merged) fuzz::violated("merge wrote *out on failure");
  if (merged) {
    hemilight_bake_pass_state_info info;
    hemilight_bake_pass_state_info_init(&info);
    std::vector<float> rgba(4 * texels * 4);
    if (hemilight_bake_pass_state_get(merged, &info, rgba.data(), rgba.size(), nullptr, nullptr, nullptr, nullptr, 0) != HEMILIGHT_OK)
      fuzz::violated("state_get of a merged state");
    fuzz::check_finite(HEMILIGHT_OK, rgba.data(), 4 * std::size_t(info.width) * std::size_t(info.height));
  }
  // A pass-2 job from the crafted state, then the finish with the crafted state and shards.
  if (state) {
    hemilight_bake_shard* jobs[2] = {nullptr, nullptr};
    for (int s = 0; s < 2; ++s) {
      const hemilight_status sj = hemilight_bake_scene_shard(&f.scene, &f.options, s, 2, 2, state, &jobs[s]);
      if (sj != HEMILIGHT_OK && jobs[s]) fuzz::violated("job wrote *out on failure");
    }
    if (jobs[0] && jobs[1]) {
      const hemilight_bake_shard* last[2] = {jobs[in.small(0, 1)], jobs[1]};
      fuzz::fill(f.irradiance, sizeof f.irradiance);
      const hemilight_status sf = hemilight_finish_sharded_bake(&f.scene, &f.options, last, 2, shards, state, nullptr);
      fuzz::check_untouched(sf, f.irradiance, sizeof f.irradiance);
      fuzz::check_finite(sf, f.irradiance, 3 * texels);
    }
    for (hemilight_bake_shard* j : jobs) hemilight_bake_shard_release(j);
  }
  hemilight_bake_pass_state_release(merged);
  hemilight_bake_pass_state_release(state);
  hemilight_bake_shard_release(shard);
  return 0;
}
