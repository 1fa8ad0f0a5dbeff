// The baker's checks (checks.hpp).
#include "checks.hpp"

#include "hemilight/cubemap.hpp"
#include "hemilight/lights.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hemilight::bake_detail {

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

void check_size(const char* who, int width, int height) {
  if (width < 1 || width > max_lightmap_size || height < 1 || height > max_lightmap_size)
    throw_invalid_argument(std::string(who) + ": lightmap size " + std::to_string(width) + " x " + std::to_string(height) +
                           " is invalid: width and height must be in [1, " + std::to_string(max_lightmap_size) + "]");
}

void check_input(const char* who, const bake_input& in, bool uvs_in_unit_square) {
  const scene_desc& d = in.scene;
  if (d.triangle_count > 0 && !d.indices) throw_invalid_argument(std::string(who) + ": indices is null");
  if (d.vertex_count > 0 && !d.positions) throw_invalid_argument(std::string(who) + ": positions is null");
  if (!d.lightmap_uvs)
    throw_invalid_argument(std::string(who) + ": the scene has no lightmap UVs (scene_desc::lightmap_uvs is null)");
  // Albedo above 1 would make the bounces diverge (scene::create only rejects negative values).
  if (d.materials)
    for (std::size_t i = 0; i < d.triangle_count; ++i)
      for (int c = 0; c < 3; ++c)
        if (!(d.materials[i].albedo[c] >= 0.0f && d.materials[i].albedo[c] <= 1.0f))
          throw_invalid_argument(std::string(who) + ": materials[" + std::to_string(i) + "].albedo = " +
                                 num(d.materials[i].albedo[c]) + " is outside [0, 1]");
  for (std::size_t i = 0; i < 3 * d.triangle_count; ++i)
    if (d.indices[i] >= d.vertex_count)
      throw_invalid_argument(std::string(who) + ": indices[" + std::to_string(i) + "] = " + std::to_string(d.indices[i]) +
                             " is out of range: " + std::to_string(d.vertex_count) + " vertices");
  constexpr float lo = -lightmap_uv_tolerance, hi = 1.0f + lightmap_uv_tolerance;
  for (std::size_t i = 0; i < d.vertex_count; ++i) {
    const glm::vec2 uv = d.lightmap_uvs[i];
    for (int c = 0; c < 2; ++c)
      if (uvs_in_unit_square ? !(uv[c] >= lo && uv[c] <= hi) : !std::isfinite(uv[c]))
        throw_invalid_argument(std::string(who) + ": lightmap_uvs[" + std::to_string(i) + "]." + (c ? "v" : "u") + " = " +
                               num(uv[c]) +
                               (uvs_in_unit_square ? " is outside [0, 1] by more than lightmap_uv_tolerance (0.001)" : " is not finite"));
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(d.positions[i][c]))
        throw_invalid_argument(std::string(who) + ": positions[" + std::to_string(i) + "] is not finite");
    if (in.normals)
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(in.normals[i][c]))
          throw_invalid_argument(std::string(who) + ": normals[" + std::to_string(i) + "] is not finite");
  }
}

void clamp_lightmap_uvs(const char* who, const bake_input& in, clamped_input& out) {
  out.input = in;
  const scene_desc& d = in.scene;
  std::size_t first = 0;
  float worst = 0.0f;
  for (std::size_t i = 0; i < d.vertex_count; ++i) {
    const glm::vec2 uv = d.lightmap_uvs[i];
    const glm::vec2 c = glm::clamp(uv, 0.0f, 1.0f);
    if (c == uv) continue;
    if (out.clamped++ == 0) {
      first = i;
      out.uvs.assign(d.lightmap_uvs, d.lightmap_uvs + d.vertex_count);
    }
    worst = std::max(worst, std::max(std::fabs(c.x - uv.x), std::fabs(c.y - uv.y)));
    out.uvs[i] = c;
  }
  if (out.clamped == 0) return;
  out.input.scene.lightmap_uvs = out.uvs.data();
  out.warning = std::string(who) + ": " + std::to_string(out.clamped) + " lightmap UV" + (out.clamped > 1 ? "s lie" : " lies") +
                " outside [0, 1] by up to " + num(worst) + " (the first: lightmap_uvs[" + std::to_string(first) +
                "]): clamped onto [0, 1] (lightmap_uv_tolerance 0.001)";
}

std::string no_uv_area_warning(const char* who, std::size_t count, const std::string& first) {
  return std::string(who) + ": " + std::to_string(count) + (count > 1 ? " triangles have" : " triangle has") +
         " 3D area but no lightmap UV area (the first: " + first + "): " + (count > 1 ? "they occlude" : "it occludes") +
         " but get" + (count > 1 ? "" : "s") + " no texels";
}

void check_options(const bake_options& o, const char* who, bool size) {
  if (size) check_size(who, o.width, o.height);
  validate_sampler_options(o.sampler, std::string(who) + ": sampler");
  if (o.bounces < 1 || o.bounces > max_bounces)
    throw_invalid_argument(std::string(who) + ": bounces " + std::to_string(o.bounces) + " is not in [1, " +
                           std::to_string(max_bounces) + "]");
  if (!(o.min_coverage >= 0.0f && o.min_coverage <= 1.0f))
    throw_invalid_argument(std::string(who) + ": min_coverage " + num(o.min_coverage) + " is not in [0, 1]");
  if (!(o.offset_texels >= 0.0f) || !std::isfinite(o.offset_texels))
    throw_invalid_argument(std::string(who) + ": offset_texels " + num(o.offset_texels) + " must be finite and >= 0");
  if (o.dilation < -1)
    throw_invalid_argument(std::string(who) + ": dilation " + std::to_string(o.dilation) + " must be >= -1");
  if (o.thread_count < 0)
    throw_invalid_argument(std::string(who) + ": thread_count " + std::to_string(o.thread_count) + " must be >= 0");
  if (!(o.ao_distance >= 0.0f) || !std::isfinite(o.ao_distance))
    throw_invalid_argument(std::string(who) + ": ao_distance " + num(o.ao_distance) +
                           " must be finite and >= 0 (scene units; 0 = no ambient occlusion)");
  validate_cache_options(o.cache, std::string(who) + ": cache");  // whatever use_cache says
  try {
    validate_lights(o.lights.data(), o.lights.size());
    validate_direct_options(o.direct);
  } catch (const error& e) {
    throw_invalid_argument(std::string(who) + ": " + e.what());
  }
  for (std::size_t c = 0; c < o.shadow_mask_lights.size(); ++c) {
    const int l = o.shadow_mask_lights[c];
    if (l < -1 || (l >= 0 && std::size_t(l) >= o.lights.size()))
      throw_invalid_argument(std::string(who) + ": shadow_mask_lights[" + std::to_string(c) + "] = " + std::to_string(l) +
                             " is not -1 or a light index (there are " + std::to_string(o.lights.size()) + " lights)");
  }
}

void check_environment(const char* who, const bake_options& o) {
  if (!o.sampler.raster.sky) return;
  try {
    o.sampler.raster.sky->validate();
  } catch (const error& e) {
    throw_invalid_argument(std::string(who) + ": sampler.raster.sky: " + e.what());
  }
}

}  // namespace hemilight::bake_detail
