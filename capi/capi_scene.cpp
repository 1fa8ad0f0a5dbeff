// The C ABI's scene entry points: hemilight_scene_create / _release / _with_environment /
// _with_lights, and the C lights (hemilight_light_init, to_lights).
#include "capi_internal.hpp"

#include "hemilight/lights.hpp"
#include "hemilight/rays.hpp"
#include "hemilight/scene.hpp"

#include <cmath>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace {

using hemilight::capi::all_finite;
using hemilight::capi::guarded;
using hemilight::capi::invalid;

}  // namespace

namespace hemilight::capi {

std::string positions_problem(const float* positions, std::size_t vertex_count, const std::string& name) {
  for (std::size_t i = 0; i < 3 * vertex_count; ++i)
    if (!(std::fabs(positions[i]) <= max_coordinate))
      return name + "[" + std::to_string(i) + "] (vertex " + std::to_string(i / 3) + ") = " + std::to_string(positions[i]) +
             "; it must be finite and at most 1e18 in magnitude";
  return {};
}

std::string indices_problem(const std::uint32_t* indices, std::size_t triangle_count, std::size_t vertex_count,
                            const std::string& name) {
  for (std::size_t i = 0; i < 3 * triangle_count; ++i)
    if (indices[i] >= vertex_count)
      return name + "[" + std::to_string(i) + "] = " + std::to_string(indices[i]) + " is out of range: " +
             std::to_string(vertex_count) + " vertices";
  return {};
}

hemilight_status to_lights(const char* function, const char* what, const hemilight_light* lights, std::size_t count,
                           std::vector<light>& out) {
  if (count > 0 && !lights) return invalid(function, std::string(what) + " is NULL but the count is " + std::to_string(count));
  std::vector<light> ls(count);
  for (std::size_t i = 0; i < count; ++i) {
    const hemilight_light& c = lights[i];
    if (c.casts_shadows != 0 && c.casts_shadows != 1)
      return invalid(function, std::string(what) + "[" + std::to_string(i) + "].casts_shadows = " +
                                   std::to_string(c.casts_shadows) + " is not 0 or 1");
    light& l = ls[i];
    // Any int is a value of light_type (its underlying type is int): validate_lights names unknown ones.
    l.type = static_cast<light_type>(enum_value(c.type));
    l.color = {c.color[0], c.color[1], c.color[2]};
    l.position = {c.position[0], c.position[1], c.position[2]};
    l.direction = {c.direction[0], c.direction[1], c.direction[2]};
    l.tangent = {c.tangent[0], c.tangent[1], c.tangent[2]};
    l.width = c.width;
    l.height = c.height;
    l.radius = c.radius;
    l.spot_inner = c.spot_inner;
    l.spot_outer = c.spot_outer;
    l.casts_shadows = c.casts_shadows == 1;
  }
  try {
    validate_lights(ls.data(), ls.size(), what);  // names the C array: "what[2].spot_outer = ..."
  } catch (const error& e) {
    return set_error(to_c(e.code()), std::string(function) + ": " + e.what());
  }
  out = std::move(ls);
  return HEMILIGHT_OK;
}

}  // namespace hemilight::capi

extern "C" {

void hemilight_light_init(hemilight_light* light, hemilight_light_type type) {
  if (!light) return;
  const hemilight::light d;  // the C++ defaults, the same values
  *light = hemilight_light{};
  std::memcpy(&light->type, &type, sizeof type);  // stored as given, even if unknown (no enum load)
  for (int k = 0; k < 3; ++k) {
    light->color[k] = d.color[k];
    light->position[k] = d.position[k];
    light->direction[k] = d.direction[k];
    light->tangent[k] = d.tangent[k];
  }
  light->width = d.width;
  light->height = d.height;
  light->radius = d.radius;
  light->spot_inner = d.spot_inner;
  light->spot_outer = d.spot_outer;
  light->casts_shadows = d.casts_shadows ? 1 : 0;
}

hemilight_status hemilight_scene_with_lights(const hemilight_scene* scene, const hemilight_light* lights, size_t count,
                                             hemilight_scene** out) {
  const char* fn = "hemilight_scene_with_lights";
  return guarded(fn, [&] {
    if (!scene) return invalid(fn, "scene is NULL");
    if (!out) return invalid(fn, "out is NULL");
    std::vector<hemilight::light> ls;
    const hemilight_status st = hemilight::capi::to_lights(fn, "lights", lights, count, ls);
    if (st != HEMILIGHT_OK) return st;
    // The ray structure now (shared by every handle of this geometry), so that an Embree failure
    // is an error here rather than slower shadow rays later.
    if (!ls.empty()) hemilight::prepare_rays(*scene->scene);
    auto handle = std::make_unique<hemilight_scene>();
    handle->scene = scene->scene;  // shared geometry and sky, not copied
    handle->sky = scene->sky;
    handle->edge_coverage = scene->edge_coverage;
    if (!ls.empty()) handle->lights = std::make_shared<const hemilight::light_set>(ls.data(), ls.size());
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_scene_create(const float* positions, size_t vertex_count, const uint32_t* indices,
                                        size_t triangle_count, const float* triangle_radiance,
                                        const float sky_radiance[3], hemilight_scene** out) {
  const char* fn = "hemilight_scene_create";
  return guarded(fn, [&] {
    if (!out) return invalid(fn, "out is NULL");
    if (!sky_radiance) return invalid(fn, "sky_radiance is NULL");
    if (vertex_count > hemilight::max_scene_elements)
      return invalid(fn, "vertex_count " + std::to_string(vertex_count) + " is over the limit of " +
                             std::to_string(hemilight::max_scene_elements));
    if (triangle_count > hemilight::max_scene_elements)
      return invalid(fn, "triangle_count " + std::to_string(triangle_count) + " is over the limit of " +
                             std::to_string(hemilight::max_scene_elements));
    if (vertex_count > 0 && !positions) return invalid(fn, "positions is NULL but vertex_count is " + std::to_string(vertex_count));
    if (triangle_count > 0 && !indices) return invalid(fn, "indices is NULL but triangle_count is " + std::to_string(triangle_count));
    if (triangle_count > 0 && !triangle_radiance)
      return invalid(fn, "triangle_radiance is NULL but triangle_count is " + std::to_string(triangle_count));
    for (int c = 0; c < 3; ++c)
      if (!(sky_radiance[c] >= 0.0f && sky_radiance[c] <= hemilight::max_radiance))
        return invalid(fn, "sky_radiance (" + std::to_string(sky_radiance[0]) + ", " + std::to_string(sky_radiance[1]) + ", " +
                               std::to_string(sky_radiance[2]) + ") must be finite, >= 0 and at most 1e30");
    for (size_t i = 0; i < 3 * triangle_count; ++i)
      if (!(triangle_radiance[i] >= 0.0f && triangle_radiance[i] <= hemilight::max_radiance))
        return invalid(fn, "triangle_radiance[" + std::to_string(i) + "] = " + std::to_string(triangle_radiance[i]) +
                               " (triangle " + std::to_string(i / 3) + "); radiance must be finite, >= 0 and at most 1e30");
    if (std::string p = hemilight::capi::positions_problem(positions, vertex_count, "positions"); !p.empty()) return invalid(fn, p);
    if (std::string p = hemilight::capi::indices_problem(indices, triangle_count, vertex_count, "indices"); !p.empty())
      return invalid(fn, p);
    // glm::vec3 is three packed floats: the caller's arrays are read in place by scene::create
    // (checked above in the caller's terms; scene::create checks them again).
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be packed");
    std::vector<hemilight::material> materials(triangle_count);
    for (size_t i = 0; i < triangle_count; ++i)
      materials[i].emission = {triangle_radiance[3 * i], triangle_radiance[3 * i + 1], triangle_radiance[3 * i + 2]};
    hemilight::scene_desc desc;
    desc.positions = reinterpret_cast<const glm::vec3*>(positions);
    desc.vertex_count = vertex_count;
    desc.indices = indices;
    desc.triangle_count = triangle_count;
    desc.materials = materials.data();
    desc.sky_radiance = {sky_radiance[0], sky_radiance[1], sky_radiance[2]};
    auto handle = std::make_unique<hemilight_scene>();
    handle->scene = hemilight::scene::create(desc);
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

void hemilight_scene_release(hemilight_scene* scene) { delete scene; }

hemilight_status hemilight_scene_with_environment(const hemilight_scene* scene, const float* faces_rgb, int size,
                                                  hemilight_scene** out) {
  const char* fn = "hemilight_scene_with_environment";
  return guarded(fn, [&] {
    if (!scene) return invalid(fn, "scene is NULL");
    if (!faces_rgb) return invalid(fn, "faces_rgb is NULL");
    if (!out) return invalid(fn, "out is NULL");
    if (size < 1 || size > hemilight::cubemap_max_size)
      return invalid(fn, "size " + std::to_string(size) + " is out of range: 1.." + std::to_string(hemilight::cubemap_max_size));
    hemilight::cube_image faces = hemilight::cube_image::make(size, 3);
    for (std::size_t i = 0; i < faces.pixels.size(); ++i) {
      if (!(faces_rgb[i] >= 0.0f && faces_rgb[i] <= hemilight::max_radiance))
        return invalid(fn, "faces_rgb[" + std::to_string(i) + "] = " + std::to_string(faces_rgb[i]) +
                               "; radiance must be finite, >= 0 and at most 1e30");
      faces.pixels[i] = faces_rgb[i];
    }
    auto handle = std::make_unique<hemilight_scene>();
    handle->scene = scene->scene;  // shared geometry and lights, not copied
    handle->lights = scene->lights;
    handle->edge_coverage = scene->edge_coverage;
    handle->sky = std::make_shared<const hemilight::cubemap>(hemilight::cubemap::from_image(std::move(faces), false));
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_scene_with_edge_coverage(const hemilight_scene* scene, int edge_coverage,
                                                    hemilight_scene** out) {
  const char* fn = "hemilight_scene_with_edge_coverage";
  return guarded(fn, [&] {
    if (!scene) return invalid(fn, "scene is NULL");
    if (!out) return invalid(fn, "out is NULL");
    if (edge_coverage != 0 && edge_coverage != 1)
      return invalid(fn, "edge_coverage is " + std::to_string(edge_coverage) + "; it must be 0 or 1");
    auto handle = std::make_unique<hemilight_scene>(*scene);  // shared geometry, sky and lights
    handle->edge_coverage = edge_coverage == 1;
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

}  // extern "C"
