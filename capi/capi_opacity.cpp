// The C ABI's opacity (hemilight.h, "opacity"): hemilight_scene_with_opacity, and the checks of C
// opacities that the scene bake shares (capi_internal.hpp). The mapping of a C opacity to the C++
// material and hemilight_opacity_init are in capi_options.cpp.
#include "capi_internal.hpp"
#include "capi_options.hpp"

#include "hemilight/rays.hpp"
#include "hemilight/scene.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace hemilight::capi {

namespace {

// The shortest decimal form that reads back as v ("1.5", "1.0000001", "nan"): a value just
// outside a range is shown as such, not rounded onto its bound.
std::string shortest(float v) {
  char text[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, double(v));
    if (!std::isfinite(v) || std::strtof(text, nullptr) == v) break;
  }
  return text;
}

std::string unit_problem(const std::string& name, float v) {
  if (v >= 0.0f && v <= 1.0f) return {};
  return name + " = " + shortest(v) + " is outside [0, 1]";
}

}  // namespace

std::string alpha_textures_problem(const hemilight_alpha_texture* textures, std::size_t count, const std::string& name) {
  if (count > 0 && !textures) return name + " is NULL but alpha_texture_count is " + std::to_string(count);
  for (std::size_t t = 0; t < count; ++t) {
    const hemilight_alpha_texture& a = textures[t];
    const std::string at = name + "[" + std::to_string(t) + "]";
    if (a.width < 1 || a.width > max_alpha_texture_size || a.height < 1 || a.height > max_alpha_texture_size)
      return at + ": width x height = " + std::to_string(a.width) + " x " + std::to_string(a.height) +
             " is invalid: each must be in [1, " + std::to_string(max_alpha_texture_size) + "]";
    if (!a.values) return at + ".values is NULL";
  }
  return {};
}

std::string opacity_problem(const hemilight_opacity& o, const std::string& name, std::size_t alpha_texture_count,
                            const std::string& textures_name, bool has_texcoords, const std::string& texcoords_name) {
  switch (o.mode) {
    case HEMILIGHT_OPAQUE: return {};  // the other fields are not used: not checked
    case HEMILIGHT_ALPHA_TESTED: {
      if (std::string p = unit_problem(name + ".alpha", o.alpha); !p.empty()) return p;
      if (std::string p = unit_problem(name + ".alpha_cutoff", o.alpha_cutoff); !p.empty()) return p;
      if (o.alpha_texture < -1 || (o.alpha_texture >= 0 && std::size_t(o.alpha_texture) >= alpha_texture_count))
        return name + ".alpha_texture = " + std::to_string(o.alpha_texture) + " is not -1 or an index into " + textures_name +
               " (alpha_texture_count " + std::to_string(alpha_texture_count) + ")";
      if (o.alpha_texture >= 0 && !has_texcoords)
        return name + ".alpha_texture = " + std::to_string(o.alpha_texture) + " names an alpha texture but " + texcoords_name +
               " is NULL (the texture is read at the texcoords)";
      return {};
    }
    case HEMILIGHT_TRANSLUCENT:
      for (int c = 0; c < 3; ++c)
        if (std::string p = unit_problem(name + ".transmittance[" + std::to_string(c) + "]", o.transmittance[c]); !p.empty())
          return p;
      return {};
    default:
      return name + ".mode = " + std::to_string(o.mode) +
             " is not HEMILIGHT_OPAQUE (0), HEMILIGHT_ALPHA_TESTED (1) or HEMILIGHT_TRANSLUCENT (2)";
  }
}

std::string texcoords_problem(const float* texcoords, std::size_t vertex_count, const std::string& name) {
  if (!texcoords) return {};
  for (std::size_t i = 0; i < 2 * vertex_count; ++i)
    if (!std::isfinite(texcoords[i]))
      return name + "[" + std::to_string(i) + "] (vertex " + std::to_string(i / 2) + ", " + (i % 2 ? "v" : "u") + ") = " +
             shortest(texcoords[i]) + "; it must be finite";
  return {};
}

std::vector<alpha_texture> alpha_texture_views(const hemilight_alpha_texture* textures, std::size_t count) {
  std::vector<alpha_texture> views(count);
  for (std::size_t t = 0; t < count; ++t) views[t] = {textures[t].values, textures[t].width, textures[t].height};
  return views;
}

}  // namespace hemilight::capi

extern "C" {

hemilight_status hemilight_scene_with_opacity(const hemilight_scene* scene, const hemilight_opacity* opacities,
                                              const float* texcoords, const hemilight_alpha_texture* alpha_textures,
                                              size_t alpha_texture_count, hemilight_scene** out) {
  const char* fn = "hemilight_scene_with_opacity";
  using hemilight::capi::invalid;
  return hemilight::capi::guarded(fn, [&] {
    if (!scene) return invalid(fn, "scene is NULL");
    if (!out) return invalid(fn, "out is NULL");
    const hemilight::scene& old = *scene->scene;
    const std::size_t triangles = old.triangle_count(), vertices = old.vertex_count();
    if (triangles > 0 && !opacities)
      return invalid(fn, "opacities is NULL but the scene has " + std::to_string(triangles) + " triangles");
    if (std::string p = hemilight::capi::alpha_textures_problem(alpha_textures, alpha_texture_count, "alpha_textures"); !p.empty())
      return invalid(fn, p);
    if (std::string p = hemilight::capi::texcoords_problem(texcoords, vertices, "texcoords"); !p.empty()) return invalid(fn, p);
    bool reads_texture = false;
    for (std::size_t i = 0; i < triangles; ++i) {
      const hemilight_opacity& o = opacities[i];
      if (std::string p = hemilight::capi::opacity_problem(o, "opacities[" + std::to_string(i) + "]", alpha_texture_count,
                                                           "alpha_textures", texcoords != nullptr, "texcoords");
          !p.empty())
        return invalid(fn, p);
      reads_texture = reads_texture || (o.mode == HEMILIGHT_ALPHA_TESTED && o.alpha_texture >= 0);
    }
    // Everything checked: the same triangles, materials and sky with the new opacities.
    std::vector<hemilight::material> materials(triangles);
    for (std::size_t i = 0; i < triangles; ++i) {
      materials[i] = old.triangle_material(i);
      hemilight::capi::apply_opacity(opacities[i], materials[i]);
    }
    static_assert(sizeof(glm::vec2) == 2 * sizeof(float), "glm::vec2 must be packed");
    const std::vector<hemilight::alpha_texture> views = hemilight::capi::alpha_texture_views(alpha_textures, alpha_texture_count);
    hemilight::scene_desc desc;
    desc.positions = old.positions().data();
    desc.vertex_count = vertices;
    desc.indices = old.indices().data();
    desc.triangle_count = triangles;
    desc.materials = materials.data();
    desc.lightmap_uvs = old.has_lightmap_uvs() ? old.lightmap_uvs().data() : nullptr;
    desc.sky_radiance = old.sky_radiance();
    desc.texcoords = reads_texture ? reinterpret_cast<const glm::vec2*>(texcoords) : nullptr;
    desc.alpha_textures = views.empty() ? nullptr : views.data();
    desc.alpha_texture_count = views.size();
    auto handle = std::make_unique<hemilight_scene>(*scene);  // the sky, lights and edge coverage
    handle->scene = hemilight::scene::create(desc);
    // As hemilight_scene_with_lights: the new geometry's ray structure now, so that an Embree
    // failure is an error here rather than slower shadow rays later.
    if (handle->lights) hemilight::prepare_rays(*handle->scene);
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

}  // extern "C"
