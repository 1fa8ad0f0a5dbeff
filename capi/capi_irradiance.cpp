// The C ABI's irradiance cache (one hemicube at a point: capi_sampler.cpp).
#include "capi_internal.hpp"
#include "capi_options.hpp"

#include "hemilight/cache.hpp"
#include "hemilight/integrate.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace {

using hemilight::capi::all_finite;
using hemilight::capi::guarded;
using hemilight::capi::invalid;

// The option fields hemilight_cache_irradiance checks itself, each named as the C caller wrote it:
// the resolution, the thread count, the 0/1 switches, the placement rules (whose C++ names differ)
// and the weight (the other ranges follow through validate_cache_options).
hemilight_status check_c_options(const char* fn, const hemilight_cache_options& o) {
  if (const hemilight_status st = hemilight::capi::check_resolution(fn, o.resolution, "options->resolution")) return st;
  if (o.thread_count < 0) return invalid(fn, "options->thread_count is " + std::to_string(o.thread_count) + "; it must be >= 0");
  const std::pair<const char*, int> switches[] = {{"use_gradients", o.use_gradients},
                                                  {"gradient_radius_limit", o.gradient_radius_limit},
                                                  {"neighbour_clamp", o.neighbour_clamp},
                                                  {"shrink_disagreeing", o.shrink_disagreeing},
                                                  {"refine_disagreement", o.refine_disagreement},
                                                  {"extrapolate_wall_depth", o.extrapolate_wall_depth},
                                                  {"second_order", o.second_order},
                                                  {"edge_coverage", o.edge_coverage}};
  for (const auto& sw : switches)
    if (sw.second != 0 && sw.second != 1)
      return invalid(fn, std::string("options->") + sw.first + " is " + std::to_string(sw.second) + "; it must be 0 or 1");
  // The placement rules' ranges (cache_expert_options), named as the C caller wrote them.
  if (!(o.second_opinion >= 0.0f) || !std::isfinite(o.second_opinion))
    return invalid(fn, "options->second_opinion is " + std::to_string(o.second_opinion) + "; it must be finite and >= 0 (0 = off)");
  if (!(o.nearby_opinion >= 0.0f && o.nearby_opinion <= 16.0f))
    return invalid(fn, "options->nearby_opinion is " + std::to_string(o.nearby_opinion) + "; it must be in [0, 16] (0 = off)");
  if (!(o.sole_record_reach > 0.0f && o.sole_record_reach <= 1.0f))
    return invalid(fn, "options->sole_record_reach is " + std::to_string(o.sole_record_reach) + "; it must be in (0, 1] (1 = off)");
  // Read as an int: a C caller may store any int in an enum field (a C++ load of such a value is
  // undefined behaviour).
  const int weight = hemilight::capi::enum_value(o.weight);
  if (weight != HEMILIGHT_CACHE_WEIGHT_WARD && weight != HEMILIGHT_CACHE_WEIGHT_TABELLION_LAMORLETTE &&
      weight != HEMILIGHT_CACHE_WEIGHT_WARD_CONTINUOUS)
    return invalid(fn, "options->weight is " + std::to_string(weight) +
                           "; it must be HEMILIGHT_CACHE_WEIGHT_WARD (0), HEMILIGHT_CACHE_WEIGHT_TABELLION_LAMORLETTE (1) "
                           "or HEMILIGHT_CACHE_WEIGHT_WARD_CONTINUOUS (2)");
  return HEMILIGHT_OK;
}

// Adds the scene's lights' direct irradiance at every point, never interpolated (parallel; each
// point's value depends on the point alone, so the result is the same for any thread count).
void add_direct_light(const hemilight_scene& scene, const glm::vec3* positions, const glm::vec3* normals, std::size_t count,
                      int thread_count, std::vector<glm::vec3>& irradiance) {
  const hemilight::scene& sc = *scene.scene;
  const hemilight::light_set& ls = *scene.lights;
  hemilight::parallel_for(count, thread_count, 256, [&](int, std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) irradiance[i] += hemilight::direct_irradiance(sc, ls, positions[i], glm::normalize(normals[i]));
  });
}

hemilight_cache_stats stats_of(const hemilight::cache_stats& s) {
  hemilight_cache_stats st;
  st.struct_size = sizeof st;
  st.hemicubes = s.hemicubes;
  st.records = s.records;
  st.seconds = s.seconds;
  st.invalid_samples = s.invalid_samples;
  return st;
}

}  // namespace

extern "C" {

hemilight_status hemilight_cache_irradiance(const hemilight_scene* scene, const float* positions, const float* normals,
                                            size_t count, const hemilight_cache_options* options, float* irradiance_rgb,
                                            hemilight_cache_stats* stats) {
  const char* fn = "hemilight_cache_irradiance";
  return guarded(fn, [&] {
    // Step 1: the arguments and every option, before the sampler builds its tables (up to GBs at
    // N = 4096).
    if (!scene) return invalid(fn, "scene is NULL");
    if (!options) return invalid(fn, "options is NULL (use hemilight_cache_options_init)");
    hemilight_cache_options full = hemilight::capi::default_cache_options();
    if (const std::string problem = hemilight::capi::read_sized(options, full); !problem.empty()) return invalid(fn, problem);
    if (stats)
      if (const std::string problem = hemilight::capi::check_sized(stats); !problem.empty()) return invalid(fn, problem);
    if (!irradiance_rgb) return invalid(fn, "irradiance_rgb is NULL");
    if (!positions) return invalid(fn, "positions is NULL");
    if (!normals) return invalid(fn, "normals is NULL");
    if (count == 0) return invalid(fn, "count is 0: there are no points");
    if (const hemilight_status st = check_c_options(fn, full)) return st;
    const hemilight::cache_options o = hemilight::capi::to_cpp(full);
    // The C++ rules (one statement of each), named from here: "hemilight_cache_irradiance:
    // options: min_radius is -1.000000; ...".
    hemilight::validate_cache_options(o, std::string(fn) + ": options");
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be packed");
    const auto* p = reinterpret_cast<const glm::vec3*>(positions);
    const auto* n = reinterpret_cast<const glm::vec3*>(normals);
    hemilight::validate_cache_points(p, n, count, fn);  // "hemilight_cache_irradiance: positions[3] = ..."
    // Step 2: the sampler and the cache.
    const hemilight::cache_run run = hemilight::capi::cache_run_of(full);
    hemilight::sampler_options so = hemilight::capi::sampler_options_of(full);
    so.raster.sky = scene->sky;
    so.raster.edge_coverage = so.raster.edge_coverage || scene->edge_coverage;
    const hemilight::irradiance_sampler sampler =
        hemilight::make_hemicube_sampler(scene->scene, so, hemilight::resolve_thread_count(run.thread_count));
    hemilight::cache_result r = hemilight::cache_irradiance(p, n, count, sampler, o, run);
    // Step 3: the lights' direct part.
    if (scene->lights) add_direct_light(*scene, p, n, count, run.thread_count, r.irradiance);
    // Step 4: the outputs, only when everything is finite (radiance is bounded by max_radiance,
    // but a light's I / d^2 next to a point is not).
    for (size_t i = 0; i < count; ++i)
      if (!all_finite(&r.irradiance[i].x, 3))
        return invalid(fn, "the irradiance at point " + std::to_string(i) +
                               " overflows float (a light too intense or too close to the point?)");
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) irradiance_rgb[3 * i + size_t(c)] = r.irradiance[i][c];
    if (stats) hemilight::capi::write_sized(stats_of(r.stats), stats);
    return HEMILIGHT_OK;
  });
}

}  // extern "C"
