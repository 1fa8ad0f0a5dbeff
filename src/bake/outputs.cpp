// The baker's outputs: the lightmap images of a bake (pipeline.hpp, steps 5 and 6) and the
// public writers of a result (bake.hpp: write_bake_exrs, bake_mask_image).
#include "dilate.hpp"
#include "pipeline.hpp"

#include <cstring>
#include <string>

namespace hemilight {

namespace bake_detail {

// Step 5 and 6: the lightmap images from the last pass (less the first with indirect_only),
// dilated around every chart.
void write_outputs(const sample_points& pts, const pass_values& last, const pass_values* first,
                   const direct_values* direct, const std::vector<std::uint8_t>& valid, const bake_options& o,
                   const bake_layout& layout, bake_result& r, std::vector<std::uint8_t>& filled) {
  const std::size_t texels = std::size_t(layout.width) * std::size_t(layout.height);
  const std::size_t count = pts.texel_of.size();
  r.irradiance = image::make(layout.width, layout.height, 3);
  r.valid.assign(texels, 0);
  filled.assign(texels, 0);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t k = pts.texel_of[i];
    glm::vec3 v = last.e[i];
    if (first) v = glm::max(v - first->e[i], glm::vec3(0.0f));
    std::memcpy(r.irradiance.pixels.data() + 3 * k, &v, sizeof v);
    filled[k] = 1;
    r.valid[k] = valid[i];
    if (!valid[i]) ++r.stats.invalid_texels;
  }
  // Per-sample values written into images, each dilated from the same mask as the irradiance.
  const auto to_image = [&](const auto& value_of) {
    image img = image::make(layout.width, layout.height, 3);
    for (std::size_t i = 0; i < count; ++i) {
      const glm::vec3 v = value_of(i);
      std::memcpy(img.pixels.data() + 3 * pts.texel_of[i], &v, sizeof v);
    }
    std::vector<std::uint8_t> f = filled;
    dilate_masked(img, f, o.dilation, layout.blocked_mask());
    return img;
  };
  if (o.output_sh_l1)
    for (std::size_t j = 0; j < 4; ++j)
      r.sh_l1[j] = to_image([&](std::size_t i) { return first ? last.sh[j][i] - first->sh[j][i] : last.sh[j][i]; });
  if (o.output_hl2) {
    std::vector<std::array<glm::vec3, 3>> h(count);
    for (std::size_t i = 0; i < count; ++i) {
      hl2_cone c = last.cone[i];
      if (first)
        for (std::size_t t = 0; t < std::size_t(hl2_cone_terms); ++t) c.coefficients[t] -= first->cone[i].coefficients[t];
      h[i] = hl2_from_cone(c, frame{pts.tangents[i], pts.bitangents[i], pts.normals[i]});
      if (direct && !first)
        for (std::size_t j = 0; j < 3; ++j) h[i][j] += direct->hl2[j][i];
    }
    for (std::size_t j = 0; j < 3; ++j) r.hl2[j] = to_image([&](std::size_t i) { return h[i][j]; });
  }
  if (direct && !direct->mask[0].empty()) {
    const image rgb = to_image([&](std::size_t i) { return direct->mask[0][i]; });
    const image alpha = to_image([&](std::size_t i) { return direct->mask[1][i]; });
    r.shadow_mask = image::make(layout.width, layout.height, 4);
    for (std::size_t k = 0; k < texels; ++k) {
      for (std::size_t c = 0; c < 3; ++c) r.shadow_mask.pixels[4 * k + c] = rgb.pixels[3 * k + c];
      r.shadow_mask.pixels[4 * k + 3] = alpha.pixels[3 * k];
    }
  }
  r.stats.dilated_texels = dilate_masked(r.irradiance, filled, o.dilation, layout.blocked_mask());
}

}  // namespace bake_detail

std::vector<std::string> write_bake_exrs(const bake_result& r, const std::string& prefix, exr_pixel_type type) {
  std::vector<std::string> written;
  const auto put = [&](const std::string& suffix, const image& img) {
    write_exr(prefix + suffix, img, type);
    written.push_back(prefix + suffix);
  };
  put("_irradiance.exr", r.irradiance);
  put("_mask.exr", bake_mask_image(r));
  for (std::size_t k = 0; k < r.sh_l1.size(); ++k)
    if (r.sh_l1[k].width > 0) put("_sh_l1_" + std::to_string(k) + ".exr", r.sh_l1[k]);
  for (std::size_t k = 0; k < r.hl2.size(); ++k)
    if (r.hl2[k].width > 0) put("_hl2_" + std::to_string(k) + ".exr", r.hl2[k]);
  if (r.shadow_mask.width > 0) put("_shadow_mask.exr", r.shadow_mask);
  return written;
}

image bake_mask_image(const bake_result& result) {
  const image& e = result.irradiance;
  const std::size_t texels = std::size_t(e.width) * std::size_t(e.height);
  if (result.coverage.size() != texels || result.valid.size() != texels || result.sampled.size() != texels)
    throw_invalid_argument("bake_mask_image: the result's per-texel arrays do not match its irradiance image");
  image m = image::make(e.width, e.height, 3);
  for (std::size_t k = 0; k < texels; ++k) {
    m.pixels[3 * k] = result.coverage[k];
    m.pixels[3 * k + 1] = float(result.valid[k]);
    m.pixels[3 * k + 2] = float(result.sampled[k]);
  }
  return m;
}

}  // namespace hemilight
