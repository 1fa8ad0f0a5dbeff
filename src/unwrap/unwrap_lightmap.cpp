// unwrap_lightmap and validate_unwrap_options (unwrap.hpp): the input's checks, then the chain of
// unwrap_internal.hpp's steps.
#include "unwrap_internal.hpp"

#include "hemilight/error.hpp"

#include <chrono>
#include <cmath>
#include <string>

namespace hemilight {

namespace {

// The checks of the mesh, naming the array and the index; out_of_memory beyond the output's
// 32-bit indices (3 vertices per triangle at most).
void check_unwrap_input(const glm::vec3* positions, std::size_t vertex_count, const std::uint32_t* indices,
                        std::size_t triangle_count) {
  const std::string who = "unwrap_lightmap: ";
  if (vertex_count > max_scene_elements)
    throw error(status::out_of_memory, who + "vertex_count " + std::to_string(vertex_count) + " is over max_scene_elements");
  if (triangle_count > max_scene_elements / 3)
    throw error(status::out_of_memory, who + "triangle_count " + std::to_string(triangle_count) +
                                           " is over max_scene_elements / 3 (the output has up to 3 vertices per triangle)");
  if (vertex_count > 0 && !positions) throw_invalid_argument(who + "positions is null with vertex_count " + std::to_string(vertex_count));
  if (triangle_count > 0 && !indices) throw_invalid_argument(who + "indices is null with triangle_count " + std::to_string(triangle_count));
  for (std::size_t v = 0; v < vertex_count; ++v)
    for (int c = 0; c < 3; ++c)
      if (!(std::fabs(positions[v][c]) <= max_coordinate))
        throw_invalid_argument(who + "positions[" + std::to_string(v) + "]." + "xyz"[c] + " is " + std::to_string(positions[v][c]) +
                               "; positions must be finite and at most 1e18 (max_coordinate) in magnitude");
  for (std::size_t i = 0; i < 3 * triangle_count; ++i)
    if (indices[i] >= vertex_count)
      throw_invalid_argument(who + "indices[" + std::to_string(i) + "] = " + std::to_string(indices[i]) + " is out of range: " +
                             std::to_string(vertex_count) + " vertices");
}

}  // namespace

void validate_unwrap_options(const unwrap_options& o, const std::string& who) {
  if (!(o.texels_per_unit >= 0.0f) || !std::isfinite(o.texels_per_unit))
    throw_invalid_argument(who + ": texels_per_unit " + std::to_string(o.texels_per_unit) + " must be finite and >= 0 (0: fit one page)");
  if (o.page_size < 16 || o.page_size > max_unwrap_page_size)
    throw_invalid_argument(who + ": page_size " + std::to_string(o.page_size) + " is not in [16, " + std::to_string(max_unwrap_page_size) + "]");
  if (o.padding < 0 || o.padding > 64 || 4 * o.padding >= o.page_size)
    throw_invalid_argument(who + ": padding " + std::to_string(o.padding) + " is not in [0, 64] or not below page_size / 4");
  if (!(o.max_chart_angle >= 1.0f && o.max_chart_angle <= 89.0f))
    throw_invalid_argument(who + ": max_chart_angle " + std::to_string(o.max_chart_angle) + " is not in [1, 89] degrees");
  if (o.max_pages < 1 || o.max_pages > 4096)
    throw_invalid_argument(who + ": max_pages " + std::to_string(o.max_pages) + " is not in [1, 4096]");
  if (o.thread_count < 0) throw_invalid_argument(who + ": thread_count " + std::to_string(o.thread_count) + " must be >= 0");
}

unwrap_result unwrap_lightmap(const glm::vec3* positions, std::size_t vertex_count, const std::uint32_t* indices,
                              std::size_t triangle_count, const unwrap_options& o) {
  using namespace unwrap_detail;
  const auto t0 = std::chrono::steady_clock::now();
  validate_unwrap_options(o, "unwrap_lightmap: options");
  check_unwrap_input(positions, vertex_count, indices, triangle_count);
  const mesh_view m{positions, vertex_count, indices, triangle_count};
  const welded_mesh w = weld_and_link(m);
  chart_set charts = grow_charts(m, w, double(o.max_chart_angle));
  chart_uvs uvs = parameterize_charts(m, w, charts, o.thread_count);
  orient_charts(uvs);
  // The density decides which cuts pay: the one asked for, or an estimate of the one a target
  // size ends at (the charts' rectangles filling 70% of the page).
  const double density = o.texels_per_unit > 0.0f ? double(o.texels_per_unit) : estimate_density(uvs, o, 0.7);
  split_sparse_charts(m, w, charts, uvs, density, o.padding);
  if (o.texels_per_unit > 0.0f)
    split_large_charts(m, w, charts, uvs, double(o.page_size - 2 * o.padding) / double(o.texels_per_unit), double(o.texels_per_unit));
  placement p;
  if (charts.size() > 0) {
    p = pack_charts(uvs, o);
  } else {
    p.pages = 1;
    p.density = double(o.texels_per_unit);
  }
  unwrap_result out;
  emit_vertices(m, w, charts, uvs, p, o.page_size, out);
  unwrap_stats& s = out.stats;
  s.charts = charts.size();
  for (std::uint8_t planar : charts.planar) s.planar_charts += planar;
  s.degenerate_triangles = w.degenerate_count;
  s.pages = p.pages;
  s.texels_per_unit = float(p.density);
  measure_unwrap(m, w, p, o.page_size, out);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace hemilight
