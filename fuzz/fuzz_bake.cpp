// libFuzzer harness: hemilight_bake_lightmap and _directional with one or two meshes (positions,
// normals, UVs, indices, materials) and the options from the bytes, lights, a shadow mask and
// ambient occlusion included. Checks the contract: finite outputs on OK, untouched ones on failure.
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::input in(data, size);
  const std::size_t meshes_n = std::size_t(in.small(1, 2));
  std::vector<std::vector<float>> pos(meshes_n), nrm(meshes_n), uv(meshes_n);
  std::vector<std::vector<std::uint32_t>> idx(meshes_n);
  std::vector<std::vector<hemilight_bake_material>> mats(meshes_n);
  std::vector<hemilight_bake_mesh> meshes(meshes_n);
  for (std::size_t m = 0; m < meshes_n; ++m) {
    const std::size_t v = std::size_t(in.small(0, 8)), t = std::size_t(in.small(0, 6));
    pos[m] = in.floats(3 * v);
    uv[m].resize(2 * v);
    for (float& f : uv[m]) f = in.small(0, 15) == 0 ? in.any_float(1.0f) : float(in.small(0, 16)) / 16.0f;
    if (in.small(0, 1)) nrm[m] = in.floats(3 * v, 1.0f);
    idx[m].resize(3 * t);
    for (std::uint32_t& i : idx[m]) i = std::uint32_t(in.small(0, 9));
    mats[m].resize(t);
    for (hemilight_bake_material& mt : mats[m]) {
      for (float& f : mt.emission) f = in.small(0, 3) == 0 ? in.any_float(2.0f) : 0.0f;
      for (float& f : mt.albedo) f = in.small(0, 7) == 0 ? in.any_float(1.0f) : float(in.small(0, 8)) / 8.0f;
      mt.two_sided = in.small(0, 2);
    }
    hemilight_bake_mesh& mesh = meshes[m];
    std::memset(&mesh, 0, sizeof mesh);
    mesh.positions = pos[m].data();
    mesh.normals = nrm[m].empty() ? nullptr : nrm[m].data();
    mesh.lightmap_uvs = uv[m].data();
    mesh.vertex_count = v;
    mesh.indices = idx[m].data();
    mesh.triangle_count = t;
    mesh.materials = in.small(0, 1) ? mats[m].data() : nullptr;
    mesh.material.albedo[0] = mesh.material.albedo[1] = mesh.material.albedo[2] = 0.5f;
  }
  hemilight_bake_options o;
  hemilight_bake_options_init(&o);
  o.width = in.small(0, 12);
  o.height = in.small(0, 12);
  o.resolution = 2 * in.small(0, 6);
  o.bounces = in.small(0, 3);
  o.indirect_only = in.small(0, 2);
  o.error_threshold = in.small(0, 3) == 0 ? in.any_float(1.0f) : 0.3f;
  o.min_coverage = in.small(0, 3) == 0 ? in.any_float(1.0f) : 0.01f;
  o.dilation = in.small(-2, 3);
  o.use_cache = in.small(0, 2);
  o.thread_count = in.small(0, 2);
  for (float& f : o.sky_radiance) f = in.any_float(2.0f);
  std::vector<hemilight_light> lights(std::size_t(in.small(0, 2)));
  for (hemilight_light& l : lights) {
    hemilight_light_init(&l, hemilight_light_type(in.small(0, 3)));
    for (float& f : l.direction) f = in.any_float();
    for (float& f : l.position) f = in.any_float();
    l.radius = in.small(0, 1) ? in.any_float(0.3f) : 0.0f;
  }
  o.lights = lights.data();
  o.light_count = lights.size();
  std::vector<float> mask;
  if (in.small(0, 1)) {
    o.shadow_mask_lights[0] = in.small(-1, 2);
    mask.resize(4 * std::size_t(std::max(o.width, 0)) * std::size_t(std::max(o.height, 0)) + 1);
    o.shadow_mask_rgba = mask.data();
    o.shadow_mask_capacity = mask.size() - 1;
    fuzz::fill(mask.data(), mask.size() * sizeof(float));
  }
  const std::size_t texels = std::size_t(std::max(o.width, 0)) * std::size_t(std::max(o.height, 0));
  std::vector<float> out(3 * texels + 1), sh(12 * texels + 1), hl2(9 * texels + 1);
  std::vector<std::uint8_t> valid(texels + 1);
  fuzz::fill(out.data(), out.size() * sizeof(float));
  fuzz::fill(sh.data(), sh.size() * sizeof(float));
  fuzz::fill(valid.data(), valid.size());
  hemilight_bake_stats st;
  hemilight_bake_stats_init(&st);
  const bool directional = in.small(0, 1) == 1;
  // Ambient occlusion, drawn last (the inputs before it keep their meaning): a distance (any float
  // at times) and a buffer of texels floats, at times one short.
  std::vector<float> ao;
  if (in.small(0, 2) == 1) {
    o.ao_distance = in.small(0, 3) == 0 ? in.any_float(2.0f) : float(in.small(1, 8)) / 8.0f;
    ao.resize(texels + 1);
    o.ao = ao.data();
    o.ao_capacity = in.small(0, 7) == 0 && texels > 0 ? texels - 1 : texels;
    fuzz::fill(ao.data(), ao.size() * sizeof(float));
  }
  const hemilight_status r =
      directional ? hemilight_bake_lightmap_directional(meshes.data(), meshes_n, &o, out.data(), 3 * texels, valid.data(), texels,
                                                        sh.data(), 12 * texels, hl2.data(), 9 * texels, &st)
                  : hemilight_bake_lightmap(meshes.data(), meshes_n, &o, out.data(), 3 * texels, valid.data(), texels, &st);
  fuzz::check_finite(r, out.data(), 3 * texels);
  fuzz::check_untouched(r, out.data(), out.size() * sizeof(float));
  fuzz::check_untouched(r, valid.data(), valid.size());
  if (directional) {
    fuzz::check_finite(r, sh.data(), 12 * texels);
    fuzz::check_untouched(r, sh.data(), sh.size() * sizeof(float));
  }
  if (!mask.empty()) {
    if (o.shadow_mask_lights[0] >= 0) fuzz::check_finite(r, mask.data(), mask.size() - 1);
    fuzz::check_untouched(r, mask.data(), mask.size() * sizeof(float));
  }
  if (!ao.empty()) {
    if (o.ao_distance > 0.0f) fuzz::check_finite(r, ao.data(), texels);
    fuzz::check_untouched(r, ao.data(), ao.size() * sizeof(float));
    if (r == HEMILIGHT_OK && o.ao_distance > 0.0f)
      for (std::size_t k = 0; k < texels; ++k)
        if (!(ao[k] >= 0.0f && ao[k] <= 1.0f)) fuzz::violated("an AO value outside [0, 1] on HEMILIGHT_OK");
    fuzz::check_untouched(HEMILIGHT_ERROR_INVALID_ARGUMENT, &ao[texels], sizeof(float));  // past the capacity: never written
  }
  return 0;
}
