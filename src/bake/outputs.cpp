// The baker's outputs: the lightmap images of a bake (pipeline.hpp, steps 5 and 6) and the
// public writers of a result (bake.hpp: write_bake_exrs, bake_mask_image).
#include "dilate.hpp"
#include "pipeline.hpp"
#include "stitch_seams.hpp"

#include <chrono>
#include <cstring>
#include <limits>
#include <memory>
#include <string>

namespace hemilight {

namespace bake_detail {

namespace {

// What the outputs are finished with: the seams' stitcher (or none) and the texels written.
struct output_finisher {
  const bake_options& o;
  const bake_layout& layout;
  const std::vector<std::uint8_t>& written;  // the sampled texels
  std::unique_ptr<seam_stitcher> stitcher;
  mutable double seconds = 0.0;  // spent stitching (bake_stats::stitch_seconds)

  // Stitches (values clamped to [lo, hi]) and dilates one image; `f` receives the texels filled.
  void finish(image& img, std::vector<std::uint8_t>& f, float lo, float hi) const {
    f = written;
    if (stitcher) {
      const auto ts = std::chrono::steady_clock::now();
      stitcher->stitch(img, f, layout.blocked_mask(), lo, hi);
      seconds += seconds_since(ts);
    }
    dilate_masked(img, f, o.dilation, layout.blocked_mask());
  }
  image finish(image img, float lo, float hi) const {
    std::vector<std::uint8_t> f;
    finish(img, f, lo, hi);
    return img;
  }
};

// Per-sample values written into an image of the layout's size (the rest 0).
template <class F>
image sample_image(const sample_points& pts, const bake_layout& layout, F&& value_of) {
  image img = image::make(layout.width, layout.height, 3);
  for (std::size_t i = 0; i < pts.texel_of.size(); ++i) {
    const glm::vec3 v = value_of(i);
    std::memcpy(img.pixels.data() + 3 * pts.texel_of[i], &v, sizeof v);
  }
  return img;
}

// The HL2 maps from the last pass's cone (less the first's with indirect_only) in each texel's
// lightmap frame, plus the lights' part; stitched together (their triples are one system) and
// dilated.
void hl2_outputs(const sample_points& pts, const pass_values& last, const pass_values* first, const direct_values* direct,
                 const output_finisher& out, bake_result& r) {
  const std::size_t count = pts.texel_of.size();
  std::vector<std::array<glm::vec3, 3>> h(count);
  for (std::size_t i = 0; i < count; ++i) {
    hl2_cone c = last.cone[i];
    if (first)
      for (std::size_t t = 0; t < std::size_t(hl2_cone_terms); ++t) c.coefficients[t] -= first->cone[i].coefficients[t];
    h[i] = hl2_from_cone(c, frame{pts.tangents[i], pts.bitangents[i], pts.normals[i]});
    if (direct && !first)
      for (std::size_t j = 0; j < 3; ++j) h[i][j] += direct->hl2[j][i];
  }
  for (std::size_t j = 0; j < 3; ++j) r.hl2[j] = sample_image(pts, out.layout, [&](std::size_t i) { return h[i][j]; });
  std::vector<std::uint8_t> f = out.written;
  if (out.stitcher) {
    const auto ts = std::chrono::steady_clock::now();
    out.stitcher->stitch_hl2(r.hl2, f, out.layout.blocked_mask());
    out.seconds += seconds_since(ts);
  }
  for (std::size_t j = 0; j < 3; ++j) {
    std::vector<std::uint8_t> fj = f;
    dilate_masked(r.hl2[j], fj, out.o.dilation, out.layout.blocked_mask());
  }
}

}  // namespace

// Steps 5 and 6: the lightmap images from the last pass (less the first with indirect_only),
// each stitched along the seams (bake_options::stitch_seams), then dilated around every chart.
void write_outputs(const sample_points& pts, const pass_values& last, const pass_values* first,
                   const direct_values* direct, const std::vector<float>& ao, const std::vector<std::uint8_t>& valid,
                   const bake_options& o, const bake_layout& layout, bake_result& r, std::vector<std::uint8_t>& filled) {
  const std::size_t texels = std::size_t(layout.width) * std::size_t(layout.height);
  const std::size_t count = pts.texel_of.size();
  r.irradiance = sample_image(pts, layout, [&](std::size_t i) { return first ? glm::max(last.e[i] - first->e[i], glm::vec3(0.0f)) : last.e[i]; });
  r.valid.assign(texels, 0);
  std::vector<std::uint8_t> written(texels, 0);
  for (std::size_t i = 0; i < count; ++i) {
    written[pts.texel_of[i]] = 1;
    r.valid[pts.texel_of[i]] = valid[i];
    if (!valid[i]) ++r.stats.invalid_texels;
  }
  output_finisher out{o, layout, written, nullptr, 0.0};
  if (o.stitch_seams && !layout.seams.empty()) {
    const auto ts = std::chrono::steady_clock::now();
    out.stitcher = std::make_unique<seam_stitcher>(layout.seams, layout.seam_pages, layout.width, o.output_hl2, r.irradiance, written,
                                                   layout.blocked_mask());
    out.seconds += seconds_since(ts);
  }
  constexpr float unbounded = std::numeric_limits<float>::max();
  if (o.output_sh_l1)
    for (std::size_t j = 0; j < 4; ++j)
      r.sh_l1[j] = out.finish(sample_image(pts, layout, [&](std::size_t i) { return first ? last.sh[j][i] - first->sh[j][i] : last.sh[j][i]; }),
                              -unbounded, unbounded);
  if (o.output_hl2) hl2_outputs(pts, last, first, direct, out, r);
  if (direct && !direct->mask[0].empty()) {
    const image rgb = out.finish(sample_image(pts, layout, [&](std::size_t i) { return direct->mask[0][i]; }), 0.0f, 1.0f);
    const image alpha = out.finish(sample_image(pts, layout, [&](std::size_t i) { return direct->mask[1][i]; }), 0.0f, 1.0f);
    r.shadow_mask = image::make(layout.width, layout.height, 4);
    for (std::size_t k = 0; k < texels; ++k) {
      for (std::size_t c = 0; c < 3; ++c) r.shadow_mask.pixels[4 * k + c] = rgb.pixels[3 * k + c];
      r.shadow_mask.pixels[4 * k + 3] = alpha.pixels[3 * k];
    }
  }
  // Ambient occlusion: one more scalar output of the stitcher (its three channels equal), kept in
  // [0, 1].
  if (!ao.empty()) r.ao = out.finish(sample_image(pts, layout, [&](std::size_t i) { return glm::vec3(ao[i]); }), 0.0f, 1.0f);
  out.finish(r.irradiance, filled, 0.0f, unbounded);
  if (out.stitcher) r.stats.seam_texels = out.stitcher->texels().size();
  r.stats.stitch_seconds += out.seconds;
  for (std::size_t k = 0; k < texels; ++k)
    if (filled[k] && !written[k]) ++r.stats.dilated_texels;
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
  if (r.ao.width > 0) put("_ao.exr", r.ao);
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
