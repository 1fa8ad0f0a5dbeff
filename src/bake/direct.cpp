// The lights in a bake (pipeline.hpp, step 3b): direct irradiance per sample, added to every
// pass, and the lights' own HL2 values and shadow mask.
#include "pipeline.hpp"

#include "hemilight/parallel.hpp"

#include <algorithm>

namespace hemilight::bake_detail {

// Step 3b: the lights' direct irradiance at every sample (parallel, in blocks so that
// cancellation stays live; deterministic: each sample's value depends on its point only).
direct_values direct_pass(const sample_points& pts, const scene& sc, const light_set& lights,
                          const bake_options& o, const std::function<bool()>& keep_going) {
  const std::size_t count = pts.texel_of.size();
  const bool mask = std::any_of(o.shadow_mask_lights.begin(), o.shadow_mask_lights.end(), [](int l) { return l >= 0; });
  direct_values d;
  d.e.assign(count, glm::vec3(0.0f));
  if (o.output_sh_l1)
    for (auto& plane : d.sh) plane.assign(count, glm::vec3(0.0f));
  if (o.output_hl2)
    for (auto& plane : d.hl2) plane.assign(count, glm::vec3(0.0f));
  if (mask)
    for (auto& plane : d.mask) plane.assign(count, glm::vec3(0.0f));
  const std::size_t block = 4096;
  for (std::size_t b = 0; b < count; b += block) {
    if (keep_going && !keep_going()) throw error(status::cancelled, "bake_lightmap: cancelled by the progress callback");
    const std::size_t end = std::min(count, b + block);
    parallel_for(end - b, o.thread_count, 64, [&](int, std::size_t lo, std::size_t hi) {
      std::vector<light_sample> per_light(lights.size());
      for (std::size_t i = b + lo; i < b + hi; ++i) {
        const glm::vec3 n = pts.normals[i];
        d.e[i] = direct_irradiance(sc, lights, pts.positions[i], n, o.direct, per_light.data());
        if (mask)
          for (std::size_t c = 0; c < 4; ++c) {
            const int l = o.shadow_mask_lights[c];
            if (l >= 0) d.mask[c / 3][i][int(c % 3)] = per_light[std::size_t(l)].visibility;
          }
        if (!o.output_sh_l1 && !o.output_hl2) continue;
        const frame f{pts.tangents[i], pts.bitangents[i], pts.normals[i]};
        std::array<glm::vec3, 3> basis{};  // the texel's HL2 vectors in world space
        if (o.output_hl2)
          for (std::size_t j = 0; j < 3; ++j) basis[j] = f.to_world(glm::vec3(hl2_basis[j][0], hl2_basis[j][1], hl2_basis[j][2]));
        for (const light_sample& ls : per_light) {
          const float cos_n = glm::dot(n, ls.direction);
          if (!(cos_n > 1e-4f)) continue;  // no light, or all of it at the horizon (E ~ 0)
          const glm::vec3 flux = ls.irradiance / cos_n;  // radiance x solid angle from direction w
          const glm::vec3& w = ls.direction;
          if (o.output_sh_l1) {
            d.sh[0][i] += 0.282094792f * flux;
            d.sh[1][i] += (0.488602512f * w.y) * flux;
            d.sh[2][i] += (0.488602512f * w.z) * flux;
            d.sh[3][i] += (0.488602512f * w.x) * flux;
          }
          if (o.output_hl2)
            for (std::size_t j = 0; j < 3; ++j) d.hl2[j][i] += std::max(0.0f, glm::dot(basis[j], w)) * flux;
        }
      }
    });
  }
  return d;
}

// A pass's irradiance (and SH, where the pass computed it) plus the lights' (step 3b).
void add_direct(const direct_values& d, pass_values& v) {
  for (std::size_t i = 0; i < v.e.size(); ++i) v.e[i] += d.e[i];
  for (std::size_t c = 0; c < 4; ++c)
    if (!v.sh[c].empty() && !d.sh[c].empty())
      for (std::size_t i = 0; i < v.e.size(); ++i) v.sh[c][i] += d.sh[c][i];
}

// The lights' HL2 values and shadow mask at samples inside geometry (valid = 0 after all passes)
// from the valid texels around them, as the passes' values are.
void fill_direct_outputs(const sample_points& pts, const std::vector<std::uint8_t>& valid, const bake_layout& layout,
                         direct_values& d) {
  std::vector<std::uint8_t> invalid(valid.size());
  for (std::size_t i = 0; i < valid.size(); ++i) invalid[i] = valid[i] ? 0 : 1;
  const invalid_filler fill(pts, invalid, layout);
  if (!fill.needed()) return;
  for (auto& plane : d.hl2)
    if (!plane.empty()) fill(plane);
  for (auto& plane : d.mask)
    if (!plane.empty()) fill(plane);
}

}  // namespace hemilight::bake_detail
