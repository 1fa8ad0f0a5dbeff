// The C ABI of the lightmap baker: meshes concatenated into one scene, bake_lightmap, outputs
// copied into the caller's buffers only after everything succeeded. The scene bake's checks and
// outputs are steps (capi_scene_bake.hpp) that the sharded bakes (capi_shards.cpp) share.
#include "capi_internal.hpp"
#include "capi_options.hpp"
#include "capi_scene_bake.hpp"

#include "hemilight/bake.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
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
// Where a mesh's UVs go: a lightmap of width x height; with `placement`, a page of a scene bake
// (page UV = uv * uv_scale + uv_offset) or, for page -1, nowhere (an occluder: no UVs needed).
struct uv_target {
  int width = 0, height = 0;
  const hemilight_bake_placement* placement = nullptr;
  bool occluder() const { return placement && placement->page < 0; }
  // The page UV of component c (0: u, 1: v) of a mesh UV, in float as bake_scene computes it.
  float map(float uv, int c) const { return placement ? uv * placement->uv_scale[c] + placement->uv_offset[c] : uv; }
};

// With `strict`, a triangle with 3D area but no UV area is a problem (without, the bake counts it).
std::string check_mesh(const hemilight_bake_mesh& mesh, const std::string& name, const uv_target& target, bool strict) {
  const int width = target.width, height = target.height;
  if (std::string p = hemilight::capi::positions_problem(mesh.positions, mesh.vertex_count, name + ".positions"); !p.empty())
    return p;
  constexpr float lo = -hemilight::lightmap_uv_tolerance, hi = 1.0f + hemilight::lightmap_uv_tolerance;
  if (!target.occluder())
    for (std::size_t i = 0; i < 2 * mesh.vertex_count; ++i) {
      const float q = target.map(mesh.lightmap_uvs[i], int(i % 2));
      if (!(q >= lo && q <= hi)) {
        if (!target.placement)
          return name + ".lightmap_uvs[" + std::to_string(i) + "] (vertex " + std::to_string(i / 2) + ", " + (i % 2 ? "v" : "u") +
                 ") = " + std::to_string(mesh.lightmap_uvs[i]) + "; it must be in [0, 1] (or at most 0.001 outside: clamped)";
        return name + ".lightmap_uvs[" + std::to_string(i) + "] (vertex " + std::to_string(i / 2) + ", " + (i % 2 ? "v" : "u") +
               ") = " + std::to_string(mesh.lightmap_uvs[i]) + " maps to " + std::to_string(q) + " in page " +
               std::to_string(target.placement->page) +
               " (uv * uv_scale + uv_offset); it must be in [0, 1] (or at most 0.001 outside: clamped)";
      }
    }
  if (mesh.normals)
    for (std::size_t i = 0; i < 3 * mesh.vertex_count; ++i)
      if (!std::isfinite(mesh.normals[i]))
        return name + ".normals[" + std::to_string(i) + "] (vertex " + std::to_string(i / 3) + ") = " +
               std::to_string(mesh.normals[i]) + "; it must be finite";
  // With strict, a triangle with 3D area but no UV area: the baker's own test (src/bake/coverage.cpp,
  // triangles_in_texels) on the UVs it bakes (clamped), so that the message names the mesh and the
  // triangle within it.
  for (std::size_t t = 0; strict && t < mesh.triangle_count && !target.occluder(); ++t) {
    const std::uint32_t* idx = mesh.indices + 3 * t;
    if (idx[0] >= mesh.vertex_count || idx[1] >= mesh.vertex_count || idx[2] >= mesh.vertex_count) continue;  // named later
    glm::dvec2 uv[3];
    glm::vec3 p[3];
    for (int k = 0; k < 3; ++k) {
      uv[k] = glm::dvec2(double(std::clamp(target.map(mesh.lightmap_uvs[2 * idx[k]], 0), 0.0f, 1.0f)) * width,
                         double(std::clamp(target.map(mesh.lightmap_uvs[2 * idx[k] + 1], 1), 0.0f, 1.0f)) * height);
      p[k] = glm::vec3(mesh.positions[3 * idx[k]], mesh.positions[3 * idx[k] + 1], mesh.positions[3 * idx[k] + 2]);
    }
    const double uv_area = 0.5 * std::fabs((uv[1].x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[1].y - uv[0].y) * (uv[2].x - uv[0].x));
    if (!hemilight::is_degenerate_triangle(p[0], p[1], p[2]) && !(uv_area > 1e-12 * double(width) * double(height)))
      return name + ": triangle " + std::to_string(t) + " (indices[" + std::to_string(3 * t) + ".." + std::to_string(3 * t + 2) +
             "]) has zero area in " + (target.placement ? "its page's" : "lightmap") +
             " UV space (but not in 3D): it would get no texels";
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
hemilight_status bake_scene(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                            hemilight_bake_stats* stats);

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

hemilight_status hemilight_bake_scene(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                      hemilight_bake_stats* stats) {
  return bake_scene(scene, options, stats);
}

}  // extern "C"

namespace {

// The optional environment sky of the options, checked and converted (null without one).
hemilight_status environment_of(const char* fn, const hemilight_bake_options& o,
                                std::shared_ptr<const hemilight::cubemap>& environment) {
  if (!o.environment_rgb) {
    if (o.environment_size != 0)
      return invalid(fn, "options->environment_size is " + std::to_string(o.environment_size) +
                             " but environment_rgb is NULL (use 0 without an environment map)");
    return HEMILIGHT_OK;
  }
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
  return HEMILIGHT_OK;
}

// The checks of the options every bake entry shares (all but the lightmap's size, which only
// hemilight_bake_lightmap reads, and the lights: to_lights), each naming the C field: the
// environment, the hemicube resolution, bounces, thresholds and counts, the switches, the sky,
// the shadow-mask indices (mask: some index names a light). Every value the C++ bake would refuse
// is refused here first, in the caller's terms.
hemilight_status check_common_options(const char* fn, const hemilight_bake_options& o,
                                      std::shared_ptr<const hemilight::cubemap>& environment, bool& mask) {
  if (const hemilight_status st = environment_of(fn, o, environment)) return st;
  if (const hemilight_status st = hemilight::capi::check_resolution(fn, o.resolution, "options->resolution")) return st;
  if (o.bounces < 1 || o.bounces > 64)
    return invalid(fn, "options->bounces " + std::to_string(o.bounces) + " is not in [1, 64]");
  if (!(o.error_threshold >= hemilight::min_error_threshold && o.error_threshold <= 1.0f))
    return invalid(fn, "options->error_threshold is " + std::to_string(o.error_threshold) + "; it must be in [0.001, 1] (checked "
                       "whatever use_cache is)");
  if (!(o.min_coverage >= 0.0f && o.min_coverage <= 1.0f))
    return invalid(fn, "options->min_coverage " + std::to_string(o.min_coverage) + " is not in [0, 1]");
  if (o.dilation < -1) return invalid(fn, "options->dilation " + std::to_string(o.dilation) + " must be >= -1 (-1: fill every texel)");
  if (o.thread_count < 0) return invalid(fn, "options->thread_count " + std::to_string(o.thread_count) + " must be >= 0 (0: all cores)");
  if (!(o.ao_distance >= 0.0f) || !std::isfinite(o.ao_distance))
    return invalid(fn, "options->ao_distance is " + std::to_string(o.ao_distance) +
                           "; it must be finite and >= 0 (scene units; 0 = no ambient occlusion)");
  const std::pair<const char*, int> switches[] = {
      {"indirect_only", o.indirect_only}, {"use_cache", o.use_cache}, {"edge_coverage", o.edge_coverage}, {"strict", o.strict},
      {"stitch_seams", o.stitch_seams}};
  for (const auto& sw : switches)
    if (sw.second != 0 && sw.second != 1)
      return invalid(fn, std::string("options->") + sw.first + " is " + std::to_string(sw.second) + "; it must be 0 or 1");
  for (int c = 0; c < 3; ++c)
    if (!(o.sky_radiance[c] >= 0.0f && o.sky_radiance[c] <= hemilight::max_radiance))
      return invalid(fn, "options->sky_radiance[" + std::to_string(c) + "] = " + std::to_string(o.sky_radiance[c]) +
                             "; it must be finite, >= 0 and at most 1e30");
  mask = false;
  for (int k = 0; k < 4; ++k) {
    const int l = o.shadow_mask_lights[k];
    if (l < -1 || (l >= 0 && std::size_t(l) >= o.light_count))
      return invalid(fn, "options->shadow_mask_lights[" + std::to_string(k) + "] = " + std::to_string(l) +
                             " is not -1 or a light index (light_count is " + std::to_string(o.light_count) + ")");
    mask = mask || l >= 0;
  }
  return HEMILIGHT_OK;
}

// The meshes concatenated into one scene (indices offset by the vertices before them), each
// checked in the caller's terms first. targets[m]: where mesh m's UVs go.
struct gathered_scene {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
  std::vector<hemilight::material> materials;
  bool any_normals = false;
  // Scene bakes with see-through triangles (add_opacity): the texcoords of every vertex (when a
  // triangle reads an alpha texture) and the views of the caller's alpha textures.
  std::vector<glm::vec2> texcoords;
  std::vector<hemilight::alpha_texture> alpha_textures;
};

hemilight_status gather_meshes(const char* fn, const hemilight_bake_mesh* meshes, size_t mesh_count,
                               const std::vector<uv_target>& targets, bool strict, gathered_scene& g, const char* prefix = "") {
  size_t total_vertices = 0, total_triangles = 0;
  for (size_t m = 0; m < mesh_count; ++m) {
    total_vertices += meshes[m].vertex_count;
    total_triangles += meshes[m].triangle_count;
    if (meshes[m].normals) g.any_normals = true;
    if (total_vertices > hemilight::max_scene_elements || total_triangles > hemilight::max_scene_elements)
      return hemilight::capi::set_error(HEMILIGHT_ERROR_OUT_OF_MEMORY,
                                        std::string(fn) + ": more than 2^31 - 1 vertices or triangles in total");
  }
  for (size_t m = 0; m < mesh_count; ++m) {
    const hemilight_bake_mesh& mesh = meshes[m];
    const std::string name = std::string(prefix) + "meshes[" + std::to_string(m) + "]";
    const bool occluder = targets[m].occluder();
    if (mesh.vertex_count > 0 && (!mesh.positions || (!mesh.lightmap_uvs && !occluder)))
      return invalid(fn, name + ": positions or lightmap_uvs is NULL with vertex_count " + std::to_string(mesh.vertex_count));
    if (mesh.triangle_count > 0 && !mesh.indices)
      return invalid(fn, name + ".indices is NULL with triangle_count " + std::to_string(mesh.triangle_count));
    if (const std::string problem = check_mesh(mesh, name, targets[m], strict); !problem.empty()) return invalid(fn, problem);
    const auto base = std::uint32_t(g.positions.size());
    for (size_t v = 0; v < mesh.vertex_count; ++v) {
      g.positions.emplace_back(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]);
      // An occluder's UVs are not read (it may have none).
      g.uvs.push_back(mesh.lightmap_uvs && !occluder ? glm::vec2(mesh.lightmap_uvs[2 * v], mesh.lightmap_uvs[2 * v + 1])
                                                     : glm::vec2(0.0f));
      if (g.any_normals)
        g.normals.push_back(mesh.normals ? glm::vec3(mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2])
                                         : glm::vec3(0.0f));  // zero: the baker falls back to the face normal
    }
    if (std::string p = hemilight::capi::indices_problem(mesh.indices, mesh.triangle_count, mesh.vertex_count, name + ".indices");
        !p.empty())
      return invalid(fn, p);
    for (size_t i = 0; i < 3 * mesh.triangle_count; ++i) g.indices.push_back(base + mesh.indices[i]);
    for (size_t t = 0; t < mesh.triangle_count; ++t)
      g.materials.push_back(to_material(mesh.materials ? mesh.materials[t] : mesh.material));
  }
  return HEMILIGHT_OK;
}

hemilight::bake_input input_of(const gathered_scene& g, const hemilight_bake_options& o) {
  hemilight::bake_input in;
  in.scene.positions = g.positions.data();
  in.scene.vertex_count = g.positions.size();
  in.scene.indices = g.indices.data();
  in.scene.triangle_count = g.materials.size();
  in.scene.materials = g.materials.data();
  in.scene.lightmap_uvs = g.uvs.data();
  in.scene.sky_radiance = glm::vec3(o.sky_radiance[0], o.sky_radiance[1], o.sky_radiance[2]);
  in.scene.texcoords = g.texcoords.empty() ? nullptr : g.texcoords.data();
  in.scene.alpha_textures = g.alpha_textures.empty() ? nullptr : g.alpha_textures.data();
  in.scene.alpha_texture_count = g.alpha_textures.size();
  in.normals = g.any_normals ? g.normals.data() : nullptr;
  return in;
}

// The C statistics of a bake of the meshes (their triangles concatenated in order): the first
// triangle without UV area named by its mesh and its index there.
hemilight_bake_stats stats_of(const hemilight::bake_stats& s, const hemilight_bake_mesh* meshes, size_t mesh_count) {
  hemilight_bake_stats st;
  st.struct_size = sizeof st;
  st.sampled_texels = s.sampled_texels;
  st.invalid_texels = s.invalid_texels;
  st.dilated_texels = s.dilated_texels;
  st.overlapping_texels = s.overlapping_texels;
  st.hemicubes = s.hemicubes;
  st.records = s.records;
  st.seconds = s.seconds;
  st.degenerate_triangles = s.degenerate_triangles;
  st.no_uv_area_triangles = s.no_uv_area_triangles;
  st.first_no_uv_area_mesh = st.first_no_uv_area_triangle = SIZE_MAX;
  st.clamped_uvs = s.clamped_uvs;
  st.seam_texels = s.seam_texels;
  st.stitch_seconds = s.stitch_seconds;
  std::size_t t = s.first_no_uv_area_triangle;
  for (size_t m = 0; t != hemilight::bake_stats::no_index && m < mesh_count; ++m) {
    if (t < meshes[m].triangle_count) {
      st.first_no_uv_area_mesh = m;
      st.first_no_uv_area_triangle = t;
      break;
    }
    t -= meshes[m].triangle_count;
  }
  return st;
}

// Finite on OK: radiance is bounded (max_radiance) but a light's I / d^2 next to a texel is not.
bool result_finite(const hemilight::bake_result& r) {
  const auto finite = [](const hemilight::image& img) { return all_finite(img.pixels.data(), img.pixels.size()); };
  bool all_ok = finite(r.irradiance);
  for (const hemilight::image& img : r.sh_l1) all_ok = all_ok && finite(img);
  for (const hemilight::image& img : r.hl2) all_ok = all_ok && finite(img);
  return all_ok;
}

// Checks a page's optional material image: every value in [0, hi].
std::string check_page_image(const float* rgb, std::size_t texels, const std::string& name, float hi, const char* range) {
  if (!rgb) return {};
  for (std::size_t i = 0; i < 3 * texels; ++i)
    if (!(rgb[i] >= 0.0f && rgb[i] <= hi))
      return name + "[" + std::to_string(i) + "] (texel " + std::to_string(i / 3) + ") = " + std::to_string(rgb[i]) +
             "; it must be " + range;
  return {};
}

hemilight::image image_of(const float* rgb, int width, int height) {
  if (!rgb) return {};
  hemilight::image img = hemilight::image::make(width, height, 3);
  std::copy(rgb, rgb + img.pixels.size(), img.pixels.begin());
  return img;
}

// ---- the stages of the bake entries -----------------------------------------------------------

// Stage 1 of every entry: the caller's options over the defaults (read_sized) into `o`, and the
// statistics' struct_size.
hemilight_status read_options(const char* fn, const hemilight_bake_options* options, const hemilight_bake_stats* stats,
                              hemilight_bake_options& o) {
  if (!options) return invalid(fn, "options is NULL (use hemilight_bake_options_init)");
  o = hemilight::capi::default_bake_options();
  if (const std::string problem = hemilight::capi::read_sized(options, o); !problem.empty()) return invalid(fn, problem);
  if (stats)
    if (const std::string problem = hemilight::capi::check_sized(stats); !problem.empty()) return invalid(fn, problem);
  return HEMILIGHT_OK;
}

// How check_page's messages name a page's fields: hemilight_bake_lightmap's own arguments
// ("options->width x height", "irradiance_capacity", "options->shadow_mask_rgba") or a page of a
// scene bake ("scene->pages[2]: width x height", "scene->pages[2].irradiance_capacity", ...).
struct page_names {
  std::string size;    // before "width x height = ..."
  std::string buffer;  // before each output buffer's and material image's name
  std::string mask;    // before "shadow_mask_rgba" and "shadow_mask_capacity"
};

// The outputs of hemilight_bake_lightmap(_directional) as the one page of a scene bake (the same
// checks and copies serve both entries).
hemilight_bake_page page_of_arguments(const hemilight_bake_options& o, float* irradiance_rgb, size_t irradiance_capacity,
                                      uint8_t* valid, size_t valid_capacity, float* sh_l1_rgb, size_t sh_l1_capacity,
                                      float* hl2_rgb, size_t hl2_capacity) {
  hemilight_bake_page page{};
  page.width = o.width;
  page.height = o.height;
  page.irradiance_rgb = irradiance_rgb;
  page.irradiance_capacity = irradiance_capacity;
  page.valid = valid;
  page.valid_capacity = valid_capacity;
  page.sh_l1_rgb = sh_l1_rgb;
  page.sh_l1_capacity = sh_l1_capacity;
  page.hl2_rgb = hl2_rgb;
  page.hl2_capacity = hl2_capacity;
  page.shadow_mask_rgba = o.shadow_mask_rgba;
  page.shadow_mask_capacity = o.shadow_mask_capacity;
  return page;
}

// A page's size, its output buffers against their capacities, the shadow mask's buffer when
// `mask` (some options->shadow_mask_lights index names a light) and its material images.
hemilight_status check_page(const char* fn, const hemilight_bake_page& page, const page_names& name, bool mask) {
  if (page.width < 1 || page.width > hemilight::max_lightmap_size || page.height < 1 || page.height > hemilight::max_lightmap_size)
    return invalid(fn, name.size + "width x height = " + std::to_string(page.width) + " x " + std::to_string(page.height) +
                           " is invalid: each must be in [1, " + std::to_string(hemilight::max_lightmap_size) + "]");
  const size_t texels = size_t(page.width) * size_t(page.height);
  if (!page.irradiance_rgb) return invalid(fn, name.buffer + "irradiance_rgb is NULL");
  const auto below = [&](const char* field, size_t capacity, size_t per_texel, const char* what) {
    return invalid(fn, name.buffer + field + " " + std::to_string(capacity) + " is below " +
                           (per_texel > 1 ? std::to_string(per_texel) + " x " : std::string()) + "width x height = " +
                           std::to_string(per_texel * texels) + what);
  };
  if (page.irradiance_capacity < 3 * texels) return below("irradiance_capacity", page.irradiance_capacity, 3, " floats");
  if (page.valid && page.valid_capacity < texels) return below("valid_capacity", page.valid_capacity, 1, "");
  if (page.sh_l1_rgb && page.sh_l1_capacity < 12 * texels)
    return below("sh_l1_capacity", page.sh_l1_capacity, 12, " floats (four RGB images)");
  if (page.hl2_rgb && page.hl2_capacity < 9 * texels) return below("hl2_capacity", page.hl2_capacity, 9, " floats (three RGB images)");
  if (mask && !page.shadow_mask_rgba)
    return invalid(fn, "options->shadow_mask_lights names a light but " + name.mask + "shadow_mask_rgba is NULL");
  if (mask && page.shadow_mask_capacity < 4 * texels)
    return invalid(fn, name.mask + "shadow_mask_capacity " + std::to_string(page.shadow_mask_capacity) +
                           " is below 4 x width x height = " + std::to_string(4 * texels) + " floats");
  if (std::string e = check_page_image(page.albedo_rgb, texels, name.buffer + "albedo_rgb", 1.0f, "in [0, 1]"); !e.empty())
    return invalid(fn, e);
  if (std::string e = check_page_image(page.emission_rgb, texels, name.buffer + "emission_rgb", hemilight::max_radiance,
                                       "finite, >= 0 and at most 1e30");
      !e.empty())
    return invalid(fn, e);
  return HEMILIGHT_OK;
}

// One page's ambient-occlusion buffer (`buffer`, `capacity` floats, named `name` and
// `capacity_name` in messages) for a page of width x height texels: required (non-NULL) for
// hemilight_bake_lightmap's options->ao, optional per page for scene bakes.
hemilight_status check_ao_buffer(const char* fn, const float* buffer, size_t capacity, size_t texels, bool required,
                                 const std::string& name, const std::string& capacity_name, float distance) {
  if (!buffer) {
    if (!required) return HEMILIGHT_OK;
    return invalid(fn, "options->ao_distance is " + std::to_string(distance) + " but " + name +
                           " is NULL (width x height floats; ao_distance 0 = no ambient occlusion)");
  }
  if (capacity < texels)
    return invalid(fn, capacity_name + " " + std::to_string(capacity) + " is below width x height = " + std::to_string(texels) +
                           " floats");
  return HEMILIGHT_OK;
}

// Copies a bake's ambient occlusion (RGB, equal channels) as one float per texel.
void write_ao(const hemilight::bake_result& r, float* out) {
  const size_t texels = r.ao.pixels.size() / 3;
  for (size_t k = 0; k < texels; ++k) out[k] = r.ao.pixels[3 * k];
}

// Copies a successful bake's images into the page's buffers (checked by check_page).
void write_page(const hemilight::bake_result& r, const hemilight_bake_page& page, bool mask) {
  const size_t texels = size_t(page.width) * size_t(page.height);
  std::copy(r.irradiance.pixels.begin(), r.irradiance.pixels.end(), page.irradiance_rgb);
  if (mask) std::copy(r.shadow_mask.pixels.begin(), r.shadow_mask.pixels.end(), page.shadow_mask_rgba);
  if (page.valid) std::copy(r.valid.begin(), r.valid.end(), page.valid);
  if (page.sh_l1_rgb)
    for (std::size_t k = 0; k < 4; ++k) std::copy(r.sh_l1[k].pixels.begin(), r.sh_l1[k].pixels.end(), page.sh_l1_rgb + 3 * texels * k);
  if (page.hl2_rgb)
    for (std::size_t k = 0; k < 3; ++k) std::copy(r.hl2[k].pixels.begin(), r.hl2[k].pixels.end(), page.hl2_rgb + 3 * texels * k);
}

const char* const overflow_message = "the irradiance overflows float (a light too intense or too close to a surface?)";

hemilight_status bake(const char* fn, const hemilight_bake_mesh* meshes, size_t mesh_count,
                      const hemilight_bake_options* options, float* irradiance_rgb, size_t irradiance_capacity,
                      uint8_t* valid, size_t valid_capacity, float* sh_l1_rgb, size_t sh_l1_capacity, float* hl2_rgb,
                      size_t hl2_capacity, hemilight_bake_stats* stats) {
  return guarded(fn, [&] {
    // Step 1: the options, the meshes' and the outputs' arguments, the lights.
    hemilight_bake_options o;
    if (const hemilight_status st = read_options(fn, options, stats, o)) return st;
    if (mesh_count == 0) return invalid(fn, "mesh_count is 0: there is nothing to bake");
    if (!meshes) return invalid(fn, "meshes is NULL");
    const hemilight_bake_page page = page_of_arguments(o, irradiance_rgb, irradiance_capacity, valid, valid_capacity, sh_l1_rgb,
                                                       sh_l1_capacity, hl2_rgb, hl2_capacity);
    std::shared_ptr<const hemilight::cubemap> environment;
    bool mask = false;
    if (const hemilight_status st = check_common_options(fn, o, environment, mask)) return st;
    if (const hemilight_status st = check_page(fn, page, {"options->", "", "options->"}, mask)) return st;
    const bool ao = o.ao_distance > 0.0f;
    if (ao)
      if (const hemilight_status st = check_ao_buffer(fn, o.ao, o.ao_capacity, size_t(o.width) * size_t(o.height), true,
                                                      "options->ao", "options->ao_capacity", o.ao_distance))
        return st;
    std::vector<hemilight::light> lights;
    if (const hemilight_status st = hemilight::capi::to_lights(fn, "options->lights", o.lights, o.light_count, lights)) return st;
    // Step 2: the meshes, checked in the caller's terms and concatenated.
    gathered_scene g;
    uv_target target;
    target.width = o.width;
    target.height = o.height;
    if (const hemilight_status st = gather_meshes(fn, meshes, mesh_count, std::vector<uv_target>(mesh_count, target), o.strict == 1, g))
      return st;
    // Step 3: the bake (whatever it still refuses reaches the caller under fn: guarded).
    const hemilight::bake_options bo =
        hemilight::capi::to_cpp(o, std::move(environment), std::move(lights), sh_l1_rgb != nullptr, hl2_rgb != nullptr);
    const hemilight::bake_result r = hemilight::bake_lightmap(input_of(g, o), bo);
    // Step 4: the outputs, only when everything is finite.
    if (!result_finite(r)) return invalid(fn, overflow_message);
    write_page(r, page, mask);
    if (ao) write_ao(r, o.ao);
    if (stats) hemilight::capi::write_sized(stats_of(r.stats, meshes, mesh_count), stats);
    return HEMILIGHT_OK;
  });
}

// The scene description's own fields (its arrays' presence, the occluders' radiance).
hemilight_status check_scene_desc(const char* fn, const hemilight_bake_scene_desc& sd) {
  if (sd.mesh_count == 0) return invalid(fn, "scene->mesh_count is 0: there is nothing to bake");
  if (!sd.meshes) return invalid(fn, "scene->meshes is NULL");
  if (!sd.placements) return invalid(fn, "scene->placements is NULL (one per mesh)");
  if (sd.page_count == 0) return invalid(fn, "scene->page_count is 0: a scene bake needs at least one page");
  if (!sd.pages) return invalid(fn, "scene->pages is NULL");
  if (sd.occluder_radiance != HEMILIGHT_OCCLUDER_EMISSION && sd.occluder_radiance != HEMILIGHT_OCCLUDER_EMISSION_PLUS_MEAN_BOUNCE)
    return invalid(fn, "scene->occluder_radiance is " + std::to_string(sd.occluder_radiance) +
                           "; it must be HEMILIGHT_OCCLUDER_EMISSION (0) or HEMILIGHT_OCCLUDER_EMISSION_PLUS_MEAN_BOUNCE (1)");
  return HEMILIGHT_OK;
}

// Where each mesh's UVs go (targets[m] for placements[m]), the placements checked.
hemilight_status placement_targets(const char* fn, const hemilight_bake_scene_desc& sd, std::vector<uv_target>& targets) {
  targets.assign(sd.mesh_count, uv_target{});
  for (size_t m = 0; m < sd.mesh_count; ++m) {
    const hemilight_bake_placement& pl = sd.placements[m];
    const std::string name = "scene->placements[" + std::to_string(m) + "]";
    if (pl.page < -1 || (pl.page >= 0 && size_t(pl.page) >= sd.page_count))
      return invalid(fn, name + ".page = " + std::to_string(pl.page) + " is not -1 (occluder only) or a page index (page_count " +
                             std::to_string(sd.page_count) + ")");
    for (int c = 0; c < 2; ++c)
      if (!std::isfinite(pl.uv_scale[c]) || !std::isfinite(pl.uv_offset[c]))
        return invalid(fn, name + ".uv_scale or uv_offset is not finite");
    targets[m].placement = &pl;
    if (pl.page >= 0) {
      targets[m].width = sd.pages[pl.page].width;
      targets[m].height = sd.pages[pl.page].height;
    }
  }
  return HEMILIGHT_OK;
}

// The scene's opacities (scene->mesh_opacity, scene->alpha_textures), checked in the caller's
// terms before anything is allocated for them; reads_texture: some triangle reads an alpha
// texture. With more vertices or triangles than a scene holds nothing is read here (gather_meshes
// refuses them next).
hemilight_status check_opacity(const char* fn, const hemilight_bake_scene_desc& sd, bool& reads_texture) {
  reads_texture = false;
  if (std::string p = hemilight::capi::alpha_textures_problem(sd.alpha_textures, sd.alpha_texture_count, "scene->alpha_textures");
      !p.empty())
    return invalid(fn, p);
  if (!sd.mesh_opacity) return HEMILIGHT_OK;
  size_t total_vertices = 0, total_triangles = 0;
  for (size_t m = 0; m < sd.mesh_count; ++m) {
    total_vertices += sd.meshes[m].vertex_count;
    total_triangles += sd.meshes[m].triangle_count;
    if (total_vertices > hemilight::max_scene_elements || total_triangles > hemilight::max_scene_elements) return HEMILIGHT_OK;
  }
  for (size_t m = 0; m < sd.mesh_count; ++m) {
    const hemilight_mesh_opacity& mo = sd.mesh_opacity[m];
    const std::string name = "scene->mesh_opacity[" + std::to_string(m) + "]";
    if (std::string p = hemilight::capi::texcoords_problem(mo.texcoords, sd.meshes[m].vertex_count, name + ".texcoords"); !p.empty())
      return invalid(fn, p);
    const auto check = [&](const hemilight_opacity& o, const std::string& field) {
      reads_texture = reads_texture || (o.mode == HEMILIGHT_ALPHA_TESTED && o.alpha_texture >= 0);
      return hemilight::capi::opacity_problem(o, name + field, sd.alpha_texture_count, "scene->alpha_textures",
                                              mo.texcoords != nullptr, name + ".texcoords");
    };
    if (!mo.opacities) {
      if (std::string p = check(mo.opacity, ".opacity"); !p.empty()) return invalid(fn, p);
      continue;
    }
    for (size_t t = 0; t < sd.meshes[m].triangle_count; ++t)
      if (std::string p = check(mo.opacities[t], ".opacities[" + std::to_string(t) + "]"); !p.empty()) return invalid(fn, p);
  }
  return HEMILIGHT_OK;
}

// The checked opacities onto the gathered triangles' materials, with the texcoords of every
// vertex (zero for meshes without: none of their triangles reads a texture) when a triangle reads
// a texture, and the textures' views.
void add_opacity(const hemilight_bake_scene_desc& sd, bool reads_texture, gathered_scene& g) {
  g.alpha_textures = hemilight::capi::alpha_texture_views(sd.alpha_textures, sd.alpha_texture_count);
  if (!sd.mesh_opacity) return;
  if (reads_texture) g.texcoords.reserve(g.positions.size());
  size_t first = 0;
  for (size_t m = 0; m < sd.mesh_count; ++m) {
    const hemilight_bake_mesh& mesh = sd.meshes[m];
    const hemilight_mesh_opacity& mo = sd.mesh_opacity[m];
    for (size_t t = 0; t < mesh.triangle_count; ++t)
      hemilight::capi::apply_opacity(mo.opacities ? mo.opacities[t] : mo.opacity, g.materials[first + t]);
    first += mesh.triangle_count;
    for (size_t v = 0; reads_texture && v < mesh.vertex_count; ++v)
      g.texcoords.push_back(mo.texcoords ? glm::vec2(mo.texcoords[2 * v], mo.texcoords[2 * v + 1]) : glm::vec2(0.0f));
  }
}

// The C++ scene bake's input: the concatenated meshes, the pages' sizes and material images, each
// mesh's triangle range and placement.
hemilight::scene_bake_input scene_input_of(const hemilight_bake_scene_desc& sd, const gathered_scene& g,
                                           const hemilight_bake_options& o) {
  hemilight::scene_bake_input in;
  in.geometry = input_of(g, o);
  in.occluders = sd.occluder_radiance == HEMILIGHT_OCCLUDER_EMISSION ? hemilight::occluder_radiance::emission
                                                                      : hemilight::occluder_radiance::emission_plus_mean_bounce;
  for (size_t p = 0; p < sd.page_count; ++p) {
    const hemilight_bake_page& page = sd.pages[p];
    hemilight::lightmap_page lp;
    lp.width = page.width;
    lp.height = page.height;
    lp.albedo = image_of(page.albedo_rgb, page.width, page.height);
    lp.emission = image_of(page.emission_rgb, page.width, page.height);
    in.pages.push_back(std::move(lp));
  }
  std::size_t first = 0;
  for (size_t m = 0; m < sd.mesh_count; ++m) {
    hemilight::bake_mesh bm;
    bm.first_triangle = first;
    bm.triangle_count = sd.meshes[m].triangle_count;
    bm.page = sd.placements[m].page;
    bm.uv_scale = glm::vec2(sd.placements[m].uv_scale[0], sd.placements[m].uv_scale[1]);
    bm.uv_offset = glm::vec2(sd.placements[m].uv_offset[0], sd.placements[m].uv_offset[1]);
    in.meshes.push_back(bm);
    first += bm.triangle_count;
  }
  return in;
}

hemilight_status bake_scene(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                            hemilight_bake_stats* stats) {
  const char* fn = "hemilight_bake_scene";
  return guarded(fn, [&] {
    // Steps 1 and 2: the description, options, pages, lights and meshes (prepare_scene_bake).
    hemilight::capi::scene_bake_call call;
    if (const hemilight_status st = hemilight::capi::prepare_scene_bake(fn, scene, options, stats, call)) return st;
    // Step 3: the bake (whatever it still refuses reaches the caller under fn: guarded).
    const hemilight::scene_bake_result r = hemilight::bake_scene(call.input, call.options);
    // Step 4: the outputs, only when every page is finite (write_scene_bake).
    return hemilight::capi::write_scene_bake(fn, call, r, stats);
  });
}

}  // namespace

namespace hemilight::capi {

hemilight_status prepare_scene_bake(const char* fn, const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                    const hemilight_bake_stats* stats, scene_bake_call& call) {
  // Step 1: the description, the options, every page, the lights.
  if (!scene) return invalid(fn, "scene is NULL (use hemilight_bake_scene_desc_init)");
  hemilight_bake_scene_desc sd = default_bake_scene_desc();
  if (const std::string problem = read_sized(scene, sd); !problem.empty()) return invalid(fn, problem);
  hemilight_bake_options o;
  if (const hemilight_status st = read_options(fn, options, stats, o)) return st;
  if (const hemilight_status st = check_scene_desc(fn, sd)) return st;
  std::shared_ptr<const hemilight::cubemap> environment;
  bool mask = false;
  if (const hemilight_status st = check_common_options(fn, o, environment, mask)) return st;
  bool want_sh = false, want_hl2 = false;
  for (size_t p = 0; p < sd.page_count; ++p) {
    const std::string name = "scene->pages[" + std::to_string(p) + "]";
    if (const hemilight_status st = check_page(fn, sd.pages[p], {name + ": ", name + ".", name + "."}, mask)) return st;
    want_sh = want_sh || sd.pages[p].sh_l1_rgb;
    want_hl2 = want_hl2 || sd.pages[p].hl2_rgb;
  }
  const bool ao = o.ao_distance > 0.0f;
  if (ao) {
    if (!sd.ao)
      return invalid(fn, "options->ao_distance is " + std::to_string(o.ao_distance) +
                             " but scene->ao is NULL (page_count pointers, each NULL or a page's width x height floats)");
    if (!sd.ao_capacity) return invalid(fn, "scene->ao_capacity is NULL (page_count capacities, in floats)");
    for (size_t p = 0; p < sd.page_count; ++p) {
      const std::string name = "scene->ao[" + std::to_string(p) + "]";
      if (const hemilight_status st =
              check_ao_buffer(fn, sd.ao[p], sd.ao_capacity[p], size_t(sd.pages[p].width) * size_t(sd.pages[p].height), false, name,
                              "scene->ao_capacity[" + std::to_string(p) + "]", o.ao_distance))
        return st;
    }
  }
  std::vector<hemilight::light> lights;
  if (const hemilight_status st = to_lights(fn, "options->lights", o.lights, o.light_count, lights)) return st;
  // Step 2: the placements, the opacities, then the meshes (checked against their pages) concatenated.
  std::vector<uv_target> targets;
  if (const hemilight_status st = placement_targets(fn, sd, targets)) return st;
  bool reads_texture = false;
  if (const hemilight_status st = check_opacity(fn, sd, reads_texture)) return st;
  const auto g = std::make_shared<gathered_scene>();
  if (const hemilight_status st = gather_meshes(fn, sd.meshes, sd.mesh_count, targets, o.strict == 1, *g, "scene->")) return st;
  add_opacity(sd, reads_texture, *g);
  call.desc = sd;
  call.mask = mask;
  call.ao = ao;
  call.input = scene_input_of(sd, *g, o);
  call.storage = g;
  call.options = to_cpp(o, std::move(environment), std::move(lights), want_sh, want_hl2);
  return HEMILIGHT_OK;
}

hemilight_status write_scene_bake(const char* fn, const scene_bake_call& call, const scene_bake_result& r, hemilight_bake_stats* stats) {
  const hemilight_bake_scene_desc& sd = call.desc;
  for (const hemilight::bake_result& page : r.pages)
    if (!result_finite(page)) return invalid(fn, overflow_message);
  for (size_t p = 0; p < sd.page_count; ++p) {
    write_page(r.pages[p], sd.pages[p], call.mask);
    if (call.ao && sd.ao[p]) write_ao(r.pages[p], sd.ao[p]);
  }
  if (stats) write_sized(stats_of(r.stats, sd.meshes, sd.mesh_count), stats);
  return HEMILIGHT_OK;
}

}  // namespace hemilight::capi
