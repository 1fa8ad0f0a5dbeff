// The C ABI of the lightmap unwrapper: hemilight_generate_lightmap_uvs (unwrap_lightmap, outputs
// copied into the caller's buffers only after everything succeeded).
#include "capi_internal.hpp"
#include "capi_options.hpp"

#include "hemilight/unwrap.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace {

using hemilight::capi::guarded;
using hemilight::capi::invalid;

// The arguments' checks, in the caller's terms, before any work: pointers, the capacity against
// its bound (3 vertices per triangle), the options (their struct_size and ranges), the stats'
// struct_size, the positions and indices.
hemilight_status check_arguments(const char* fn, const float* positions, size_t vertex_count, const uint32_t* indices,
                                 size_t triangle_count, const hemilight_unwrap_options* options, const uint32_t* vertex_source,
                                 const float* uvs, size_t vertex_capacity, const uint32_t* out_indices,
                                 const size_t* vertex_count_out, const hemilight_unwrap_stats* stats,
                                 hemilight::unwrap_options& cpp) {
  hemilight_unwrap_options o = hemilight::capi::default_unwrap_options();
  if (options)
    if (const std::string problem = hemilight::capi::read_sized(options, o); !problem.empty()) return invalid(fn, problem);
  if (stats)
    if (const std::string problem = hemilight::capi::check_sized(stats); !problem.empty()) return invalid(fn, problem);
  cpp = hemilight::capi::to_cpp(o);
  hemilight::validate_unwrap_options(cpp, std::string(fn) + ": options");
  if (!vertex_count_out) return invalid(fn, "vertex_count_out is NULL");
  if (vertex_count > hemilight::max_scene_elements || triangle_count > hemilight::max_scene_elements / 3)
    return hemilight::capi::set_error(HEMILIGHT_ERROR_OUT_OF_MEMORY, std::string(fn) + ": more than 2^31 - 1 vertices or (2^31 - 1) / 3 "
                                                                                     "triangles (the output has up to 3 vertices per triangle)");
  if (vertex_count > 0 && !positions) return invalid(fn, "positions is NULL with vertex_count " + std::to_string(vertex_count));
  if (triangle_count > 0 && !indices) return invalid(fn, "indices is NULL with triangle_count " + std::to_string(triangle_count));
  if (triangle_count > 0 && (!vertex_source || !uvs || !out_indices))
    return invalid(fn, "vertex_source, uvs or out_indices is NULL with triangle_count " + std::to_string(triangle_count));
  if (vertex_capacity < 3 * triangle_count)
    return invalid(fn, "vertex_capacity " + std::to_string(vertex_capacity) + " is below 3 x triangle_count = " +
                           std::to_string(3 * triangle_count) + " (the most output vertices there can be)");
  if (std::string p = hemilight::capi::positions_problem(positions, vertex_count, "positions"); !p.empty()) return invalid(fn, p);
  if (std::string p = hemilight::capi::indices_problem(indices, triangle_count, vertex_count, "indices"); !p.empty())
    return invalid(fn, p);
  return HEMILIGHT_OK;
}

hemilight_unwrap_stats stats_of(const hemilight::unwrap_stats& s) {
  hemilight_unwrap_stats st;
  std::memset(&st, 0, sizeof st);
  st.struct_size = sizeof st;
  st.charts = s.charts;
  st.planar_charts = s.planar_charts;
  st.degenerate_triangles = s.degenerate_triangles;
  st.pages = s.pages;
  st.texels_per_unit = s.texels_per_unit;
  st.uv_area_fraction = s.uv_area_fraction;
  st.stretch_l2 = s.stretch_l2;
  st.stretch_linf = s.stretch_linf;
  st.seam_texels = s.seam_texels;
  st.seconds = s.seconds;
  return st;
}

}  // namespace

extern "C" hemilight_status hemilight_generate_lightmap_uvs(const float* positions, size_t vertex_count, const uint32_t* indices,
                                                           size_t triangle_count, const hemilight_unwrap_options* options,
                                                           uint32_t* vertex_source, float* uvs, size_t vertex_capacity,
                                                           uint32_t* out_indices, uint32_t* triangle_page, size_t* vertex_count_out,
                                                           hemilight_unwrap_stats* stats) {
  const char* fn = "hemilight_generate_lightmap_uvs";
  return guarded(fn, [&] {
    hemilight::unwrap_options o;
    if (const hemilight_status st = check_arguments(fn, positions, vertex_count, indices, triangle_count, options, vertex_source, uvs,
                                                    vertex_capacity, out_indices, vertex_count_out, stats, o))
      return st;
    std::vector<glm::vec3> p(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) p[v] = glm::vec3(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    const hemilight::unwrap_result r = hemilight::unwrap_lightmap(p.data(), vertex_count, indices, triangle_count, o);
    std::copy(r.vertex_source.begin(), r.vertex_source.end(), vertex_source);
    for (size_t i = 0; i < r.uvs.size(); ++i) {
      uvs[2 * i] = r.uvs[i].x;
      uvs[2 * i + 1] = r.uvs[i].y;
    }
    std::copy(r.indices.begin(), r.indices.end(), out_indices);
    if (triangle_page) std::copy(r.triangle_page.begin(), r.triangle_page.end(), triangle_page);
    *vertex_count_out = r.uvs.size();
    if (stats) hemilight::capi::write_sized(stats_of(r.stats), stats);
    return HEMILIGHT_OK;
  });
}
