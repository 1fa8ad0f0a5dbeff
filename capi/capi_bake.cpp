// The C ABI of the lightmap baker: meshes concatenated into one scene, bake_lightmap, outputs
// copied into the caller's buffers only after everything succeeded.
#include "capi_internal.hpp"
#include "capi_options.hpp"

#include "hemilight/bake.hpp"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace {

using hemilight::capi::all_finite;
using hemilight::capi::guarded;
using hemilight::capi::invalid;

// What is wrong with one material, in the caller's terms ("meshes[1].materials[3].emission[2] = -1
// ..."), or "".
std::string check_material(const hemilight_bake_material& m, const std::string& name) {
  for (int c = 0; c < 3; ++c) {
    if (!(m.emission[c] >= 0.0f && m.emission[c] <= hemilight::max_radiance))
      return name + ".emission[" + std::to_string(c) + "] = " + std::to_string(m.emission[c]) +
             "; it must be finite, >= 0 and at most 1e30";
    if (!(m.albedo[c] >= 0.0f && m.albedo[c] <= 1.0f))
      return name + ".albedo[" + std::to_string(c) + "] = " + std::to_string(m.albedo[c]) + "; it must be in [0, 1]";
  }
  if (m.two_sided != 0 && m.two_sided != 1) return name + ".two_sided = " + std::to_string(m.two_sided) + "; it must be 0 or 1";
  return {};
}

// What is wrong with one mesh's arrays, naming the mesh and the index within it, or "". (The
// baker checks the concatenated scene again; these checks keep the messages in the caller's terms.)
std::string check_mesh(const hemilight_bake_mesh& mesh, const std::string& name, int width, int height) {
  for (std::size_t i = 0; i < 3 * mesh.vertex_count; ++i)
    if (!(std::fabs(mesh.positions[i]) <= hemilight::max_coordinate))
      return name + ".positions[" + std::to_string(i) + "] (vertex " + std::to_string(i / 3) + ") = " +
             std::to_string(mesh.positions[i]) + "; it must be finite and at most 1e18 in magnitude";
  for (std::size_t i = 0; i < 2 * mesh.vertex_count; ++i)
    if (!(mesh.lightmap_uvs[i] >= 0.0f && mesh.lightmap_uvs[i] <= 1.0f))
      return name + ".lightmap_uvs[" + std::to_string(i) + "] (vertex " + std::to_string(i / 2) + ", " + (i % 2 ? "v" : "u") +
             ") = " + std::to_string(mesh.lightmap_uvs[i]) + "; it must be in [0, 1]";
  if (mesh.normals)
    for (std::size_t i = 0; i < 3 * mesh.vertex_count; ++i)
      if (!std::isfinite(mesh.normals[i]))
        return name + ".normals[" + std::to_string(i) + "] (vertex " + std::to_string(i / 3) + ") = " +
               std::to_string(mesh.normals[i]) + "; it must be finite";
  // A triangle with 3D area but no UV area: the baker's own test (bake.cpp, make_tri), computed the
  // same way, so that the message names the mesh and the triangle within it.
  for (std::size_t t = 0; t < mesh.triangle_count; ++t) {
    const std::uint32_t* idx = mesh.indices + 3 * t;
    if (idx[0] >= mesh.vertex_count || idx[1] >= mesh.vertex_count || idx[2] >= mesh.vertex_count) continue;  // named later
    glm::dvec2 uv[3];
    glm::dvec3 p[3];
    for (int k = 0; k < 3; ++k) {
      uv[k] = glm::dvec2(double(mesh.lightmap_uvs[2 * idx[k]]) * width, double(mesh.lightmap_uvs[2 * idx[k] + 1]) * height);
      p[k] = glm::dvec3(glm::vec3(mesh.positions[3 * idx[k]], mesh.positions[3 * idx[k] + 1], mesh.positions[3 * idx[k] + 2]));
    }
    const double uv_area = 0.5 * std::fabs((uv[1].x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[1].y - uv[0].y) * (uv[2].x - uv[0].x));
    const double area3 = 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
    if (area3 > 0.0 && !(uv_area > 1e-12 * double(width) * double(height)))
      return name + ": triangle " + std::to_string(t) + " (indices[" + std::to_string(3 * t) + ".." + std::to_string(3 * t + 2) +
             "]) has zero area in lightmap UV space (but not in 3D): it would get no texels";
  }
  if (mesh.materials) {
    for (std::size_t t = 0; t < mesh.triangle_count; ++t)
      if (std::string p = check_material(mesh.materials[t], name + ".materials[" + std::to_string(t) + "]"); !p.empty()) return p;
  } else if (std::string p = check_material(mesh.material, name + ".material"); !p.empty()) {
    return p;
  }
  return {};
}

hemilight::material to_material(const hemilight_bake_material& m) {
  hemilight::material r;
  r.emission = glm::vec3(m.emission[0], m.emission[1], m.emission[2]);
  r.albedo = glm::vec3(m.albedo[0], m.albedo[1], m.albedo[2]);
  r.two_sided = m.two_sided != 0;
  return r;
}

hemilight_status bake(const char* fn, const hemilight_bake_mesh* meshes, size_t mesh_count,
                      const hemilight_bake_options* options, float* irradiance_rgb, size_t irradiance_capacity,
                      uint8_t* valid, size_t valid_capacity, float* sh_l1_rgb, size_t sh_l1_capacity, float* hl2_rgb,
                      size_t hl2_capacity, hemilight_bake_stats* stats);

}  // namespace

extern "C" {

hemilight_status hemilight_bake_lightmap(const hemilight_bake_mesh* meshes, size_t mesh_count,
                                         const hemilight_bake_options* options, float* irradiance_rgb,
                                         size_t irradiance_capacity, uint8_t* valid, size_t valid_capacity,
                                         hemilight_bake_stats* stats) {
  return bake("hemilight_bake_lightmap", meshes, mesh_count, options, irradiance_rgb, irradiance_capacity, valid,
              valid_capacity, nullptr, 0, nullptr, 0, stats);
}

hemilight_status hemilight_bake_lightmap_directional(const hemilight_bake_mesh* meshes, size_t mesh_count,
                                                     const hemilight_bake_options* options, float* irradiance_rgb,
                                                     size_t irradiance_capacity, uint8_t* valid, size_t valid_capacity,
                                                     float* sh_l1_rgb, size_t sh_l1_capacity, float* hl2_rgb,
                                                     size_t hl2_capacity, hemilight_bake_stats* stats) {
  return bake("hemilight_bake_lightmap_directional", meshes, mesh_count, options, irradiance_rgb, irradiance_capacity,
              valid, valid_capacity, sh_l1_rgb, sh_l1_capacity, hl2_rgb, hl2_capacity, stats);
}

}  // extern "C"

namespace {

hemilight_status bake(const char* fn, const hemilight_bake_mesh* meshes, size_t mesh_count,
                      const hemilight_bake_options* options, float* irradiance_rgb, size_t irradiance_capacity,
                      uint8_t* valid, size_t valid_capacity, float* sh_l1_rgb, size_t sh_l1_capacity, float* hl2_rgb,
                      size_t hl2_capacity, hemilight_bake_stats* stats) {
  return guarded(fn, [&] {
    if (!options) return invalid(fn, "options is NULL (use hemilight_bake_options_init)");
    hemilight_bake_options full = hemilight::capi::default_bake_options();
    if (const std::string problem = hemilight::capi::read_sized(options, full); !problem.empty()) return invalid(fn, problem);
    if (stats)
      if (const std::string problem = hemilight::capi::check_sized(stats); !problem.empty()) return invalid(fn, problem);
    if (mesh_count == 0) return invalid(fn, "mesh_count is 0: there is nothing to bake");
    if (!meshes) return invalid(fn, "meshes is NULL");
    if (!irradiance_rgb) return invalid(fn, "irradiance_rgb is NULL");
    const hemilight_bake_options& o = full;
    if (o.width < 1 || o.width > hemilight::max_lightmap_size || o.height < 1 || o.height > hemilight::max_lightmap_size)
      return invalid(fn, "options->width x height = " + std::to_string(o.width) + " x " + std::to_string(o.height) +
                             " is invalid: each must be in [1, " + std::to_string(hemilight::max_lightmap_size) + "]");
    const size_t texels = size_t(o.width) * size_t(o.height);
    if (irradiance_capacity < 3 * texels)
      return invalid(fn, "irradiance_capacity " + std::to_string(irradiance_capacity) + " is below 3 x width x height = " +
                             std::to_string(3 * texels) + " floats");
    if (valid && valid_capacity < texels)
      return invalid(fn, "valid_capacity " + std::to_string(valid_capacity) + " is below width x height = " + std::to_string(texels));
    if (sh_l1_rgb && sh_l1_capacity < 12 * texels)
      return invalid(fn, "sh_l1_capacity " + std::to_string(sh_l1_capacity) + " is below 12 x width x height = " +
                             std::to_string(12 * texels) + " floats (four RGB images)");
    if (hl2_rgb && hl2_capacity < 9 * texels)
      return invalid(fn, "hl2_capacity " + std::to_string(hl2_capacity) + " is below 9 x width x height = " +
                             std::to_string(9 * texels) + " floats (three RGB images)");
    std::shared_ptr<const hemilight::cubemap> environment;
    if (o.environment_rgb) {
      if (o.environment_size < 1 || o.environment_size > hemilight::cubemap_max_size)
        return invalid(fn, "options->environment_size " + std::to_string(o.environment_size) + " is out of range: 1.." +
                               std::to_string(hemilight::cubemap_max_size) + " with an environment map");
      hemilight::cube_image faces = hemilight::cube_image::make(o.environment_size, 3);
      for (std::size_t i = 0; i < faces.pixels.size(); ++i) {
        const float v = o.environment_rgb[i];
        if (!(v >= 0.0f && v <= hemilight::max_radiance))
          return invalid(fn, "options->environment_rgb[" + std::to_string(i) + "] = " + std::to_string(v) +
                                 "; radiance must be finite, >= 0 and at most 1e30");
        faces.pixels[i] = v;
      }
      environment = std::make_shared<const hemilight::cubemap>(hemilight::cubemap::from_image(std::move(faces), false));
    } else if (o.environment_size != 0) {
      return invalid(fn, "options->environment_size is " + std::to_string(o.environment_size) +
                             " but environment_rgb is NULL (use 0 without an environment map)");
    }
    if (!(o.error_threshold >= hemilight::min_error_threshold && o.error_threshold <= 1.0f))
      return invalid(fn, "options->error_threshold is " + std::to_string(o.error_threshold) + "; it must be in [0.001, 1] (checked "
                         "whatever use_cache is)");
    for (const char* f : {"indirect_only", "use_cache"}) {
      const int v = std::string(f) == "use_cache" ? o.use_cache : o.indirect_only;
      if (v != 0 && v != 1) return invalid(fn, std::string("options->") + f + " is " + std::to_string(v) + "; it must be 0 or 1");
    }
    for (int c = 0; c < 3; ++c)
      if (!(o.sky_radiance[c] >= 0.0f && o.sky_radiance[c] <= hemilight::max_radiance))
        return invalid(fn, "options->sky_radiance[" + std::to_string(c) + "] = " + std::to_string(o.sky_radiance[c]) +
                               "; it must be finite, >= 0 and at most 1e30");
    bool mask = false;
    for (int k = 0; k < 4; ++k) {
      const int l = o.shadow_mask_lights[k];
      if (l < -1 || (l >= 0 && std::size_t(l) >= o.light_count))
        return invalid(fn, "options->shadow_mask_lights[" + std::to_string(k) + "] = " + std::to_string(l) +
                               " is not -1 or a light index (light_count is " + std::to_string(o.light_count) + ")");
      mask = mask || l >= 0;
    }
    if (mask && !o.shadow_mask_rgba)
      return invalid(fn, "options->shadow_mask_lights names a light but options->shadow_mask_rgba is NULL");
    if (mask && o.shadow_mask_capacity < 4 * texels)
      return invalid(fn, "options->shadow_mask_capacity " + std::to_string(o.shadow_mask_capacity) +
                             " is below 4 x width x height = " + std::to_string(4 * texels) + " floats");
    std::vector<hemilight::light> lights;
    const hemilight_status lights_status = hemilight::capi::to_lights(fn, "options->lights", o.lights, o.light_count, lights);
    if (lights_status != HEMILIGHT_OK) return lights_status;

    // Concatenate the meshes (indices offset by the vertices before them).
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::vec2> uvs;
    std::vector<std::uint32_t> indices;
    std::vector<hemilight::material> materials;
    bool any_normals = false;
    size_t total_vertices = 0, total_triangles = 0;
    for (size_t m = 0; m < mesh_count; ++m) {
      total_vertices += meshes[m].vertex_count;
      total_triangles += meshes[m].triangle_count;
      if (meshes[m].normals) any_normals = true;
      if (total_vertices > hemilight::max_scene_elements || total_triangles > hemilight::max_scene_elements)
        return hemilight::capi::set_error(HEMILIGHT_ERROR_OUT_OF_MEMORY,
                                          std::string(fn) + ": more than 2^31 - 1 vertices or triangles in total");
    }
    for (size_t m = 0; m < mesh_count; ++m) {
      const hemilight_bake_mesh& mesh = meshes[m];
      const std::string name = "meshes[" + std::to_string(m) + "]";
      if (mesh.vertex_count > 0 && (!mesh.positions || !mesh.lightmap_uvs))
        return invalid(fn, name + ": positions or lightmap_uvs is NULL with vertex_count " + std::to_string(mesh.vertex_count));
      if (mesh.triangle_count > 0 && !mesh.indices)
        return invalid(fn, name + ".indices is NULL with triangle_count " + std::to_string(mesh.triangle_count));
      if (const std::string problem = check_mesh(mesh, name, o.width, o.height); !problem.empty()) return invalid(fn, problem);
      const auto base = std::uint32_t(positions.size());
      for (size_t v = 0; v < mesh.vertex_count; ++v) {
        positions.emplace_back(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]);
        uvs.emplace_back(mesh.lightmap_uvs[2 * v], mesh.lightmap_uvs[2 * v + 1]);
        if (any_normals)
          normals.push_back(mesh.normals ? glm::vec3(mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2])
                                         : glm::vec3(0.0f));  // zero: the baker falls back to the face normal
      }
      for (size_t i = 0; i < 3 * mesh.triangle_count; ++i) {
        if (mesh.indices[i] >= mesh.vertex_count)
          return invalid(fn, name + ".indices[" + std::to_string(i) + "] = " + std::to_string(mesh.indices[i]) +
                                 " is out of range: " + std::to_string(mesh.vertex_count) + " vertices");
        indices.push_back(base + mesh.indices[i]);
      }
      for (size_t t = 0; t < mesh.triangle_count; ++t)
        materials.push_back(to_material(mesh.materials ? mesh.materials[t] : mesh.material));
    }
    hemilight::bake_input in;
    in.scene.positions = positions.data();
    in.scene.vertex_count = positions.size();
    in.scene.indices = indices.data();
    in.scene.triangle_count = materials.size();
    in.scene.materials = materials.data();
    in.scene.lightmap_uvs = uvs.data();
    in.scene.sky_radiance = glm::vec3(o.sky_radiance[0], o.sky_radiance[1], o.sky_radiance[2]);
    in.normals = any_normals ? normals.data() : nullptr;
    const hemilight::bake_options bo =
        hemilight::capi::to_cpp(o, std::move(environment), std::move(lights), sh_l1_rgb != nullptr, hl2_rgb != nullptr);
    hemilight::bake_result r;
    try {
      r = hemilight::bake_lightmap(in, bo);
    } catch (const hemilight::error& e) {
      return hemilight::capi::set_error(hemilight::capi::to_c(e.code()), std::string("hemilight_") + e.what());
    }
    // Finite on OK: radiance is bounded (max_radiance) but a light's I / d^2 next to a texel is not.
    const auto finite = [](const hemilight::image& img) { return all_finite(img.pixels.data(), img.pixels.size()); };
    bool all_ok = finite(r.irradiance);
    for (const hemilight::image& img : r.sh_l1) all_ok = all_ok && finite(img);
    for (const hemilight::image& img : r.hl2) all_ok = all_ok && finite(img);
    if (!all_ok) return invalid(fn, "the irradiance overflows float (a light too intense or too close to a surface?)");
    std::copy(r.irradiance.pixels.begin(), r.irradiance.pixels.end(), irradiance_rgb);
    if (mask) std::copy(r.shadow_mask.pixels.begin(), r.shadow_mask.pixels.end(), o.shadow_mask_rgba);
    if (valid) std::copy(r.valid.begin(), r.valid.end(), valid);
    if (sh_l1_rgb)
      for (std::size_t k = 0; k < 4; ++k) std::copy(r.sh_l1[k].pixels.begin(), r.sh_l1[k].pixels.end(), sh_l1_rgb + 3 * texels * k);
    if (hl2_rgb)
      for (std::size_t k = 0; k < 3; ++k) std::copy(r.hl2[k].pixels.begin(), r.hl2[k].pixels.end(), hl2_rgb + 3 * texels * k);
    if (stats) {
      hemilight_bake_stats st;
      st.struct_size = sizeof st;
      st.sampled_texels = r.stats.sampled_texels;
      st.invalid_texels = r.stats.invalid_texels;
      st.dilated_texels = r.stats.dilated_texels;
      st.overlapping_texels = r.stats.overlapping_texels;
      st.hemicubes = r.stats.hemicubes;
      st.records = r.stats.records;
      st.seconds = r.stats.seconds;
      hemilight::capi::write_sized(st, stats);
    }
    return HEMILIGHT_OK;
  });
}

}  // namespace
