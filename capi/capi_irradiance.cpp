// The C ABI's irradiance cache (one hemicube at a point: capi_sampler.cpp).
#include "capi_internal.hpp"

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

}  // namespace

extern "C" {

void hemilight_cache_options_init(hemilight_cache_options* options) {
  if (!options) return;
  options->resolution = 64;
  options->error_threshold = 0.2f;
  options->min_radius = 0.0f;
  options->max_radius = 0.0f;
  options->use_gradients = 1;
  options->thread_count = 0;
  options->progress = nullptr;
  options->progress_user = nullptr;
  const hemilight::cache_options d;
  options->weight = HEMILIGHT_CACHE_WEIGHT_WARD;
  options->gradient_radius_limit = d.gradient_radius_limit ? 1 : 0;
  options->neighbour_clamp = d.neighbour_clamp ? 1 : 0;
  options->shrink_disagreeing = d.shrink_disagreeing ? 1 : 0;
  options->refine_disagreement = d.refine_disagreement ? 1 : 0;
  options->second_opinion = d.second_opinion;
  options->nearby_opinion = d.nearby_opinion;
  options->sole_record_reach = d.sole_record_reach;
  options->invalid_backface_fraction = d.invalid_backface_fraction;
  options->extrapolate_wall_depth = hemilight::integrate_options{}.extrapolate_wall_depth ? 1 : 0;
  options->second_order = d.second_order ? 1 : 0;
}

hemilight_status hemilight_cache_irradiance(const hemilight_scene* scene, const float* positions, const float* normals,
                                            size_t count, const hemilight_cache_options* options, float* irradiance_rgb,
                                            hemilight_cache_stats* stats) {
  const char* fn = "hemilight_cache_irradiance";
  return guarded(fn, [&] {
    if (!scene) return invalid(fn, "scene is NULL");
    if (!options) return invalid(fn, "options is NULL (use hemilight_cache_options_init)");
    if (!irradiance_rgb) return invalid(fn, "irradiance_rgb is NULL");
    if (!positions) return invalid(fn, "positions is NULL");
    if (!normals) return invalid(fn, "normals is NULL");
    if (count == 0) return invalid(fn, "count is 0: there are no points");
    if (!hemilight::is_valid_hemicube_resolution(options->resolution))
      return invalid(fn, "options->resolution " + std::to_string(options->resolution) +
                             " is invalid: it must be even and in [2, 4096]");
    if (options->thread_count < 0)
      return invalid(fn, "options->thread_count is " + std::to_string(options->thread_count) + "; it must be >= 0");
    const std::pair<const char*, int> switches[] = {{"use_gradients", options->use_gradients},
                                                    {"gradient_radius_limit", options->gradient_radius_limit},
                                                    {"neighbour_clamp", options->neighbour_clamp},
                                                    {"shrink_disagreeing", options->shrink_disagreeing},
                                                    {"refine_disagreement", options->refine_disagreement},
                                                    {"extrapolate_wall_depth", options->extrapolate_wall_depth},
                                                    {"second_order", options->second_order}};
    for (const auto& sw : switches)
      if (sw.second != 0 && sw.second != 1)
        return invalid(fn, std::string("options->") + sw.first + " is " + std::to_string(sw.second) + "; it must be 0 or 1");
    // Read as an int: a C caller may store any int in an enum field (a C++ load of such a value is
    // undefined behaviour).
    const int weight = hemilight::capi::enum_value(options->weight);
    if (weight != HEMILIGHT_CACHE_WEIGHT_WARD && weight != HEMILIGHT_CACHE_WEIGHT_TABELLION_LAMORLETTE &&
        weight != HEMILIGHT_CACHE_WEIGHT_WARD_CONTINUOUS)
      return invalid(fn, "options->weight is " + std::to_string(weight) +
                             "; it must be HEMILIGHT_CACHE_WEIGHT_WARD (0), HEMILIGHT_CACHE_WEIGHT_TABELLION_LAMORLETTE (1) "
                             "or HEMILIGHT_CACHE_WEIGHT_WARD_CONTINUOUS (2)");
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be packed");
    hemilight::cache_options o;
    o.error_threshold = options->error_threshold;
    o.min_radius = options->min_radius;
    o.max_radius = options->max_radius;
    o.use_gradients = options->use_gradients == 1;
    o.thread_count = options->thread_count;
    o.weight = weight == HEMILIGHT_CACHE_WEIGHT_WARD                   ? hemilight::cache_weight::ward
               : weight == HEMILIGHT_CACHE_WEIGHT_TABELLION_LAMORLETTE ? hemilight::cache_weight::tabellion_lamorlette
                                                                       : hemilight::cache_weight::ward_continuous;
    o.gradient_radius_limit = options->gradient_radius_limit == 1;
    o.neighbour_clamp = options->neighbour_clamp == 1;
    o.shrink_disagreeing = options->shrink_disagreeing == 1;
    o.refine_disagreement = options->refine_disagreement == 1;
    o.second_order = options->second_order == 1;
    // Range-checked (with the field named) by cache_irradiance.
    o.second_opinion = options->second_opinion;
    o.nearby_opinion = options->nearby_opinion;
    o.sole_record_reach = options->sole_record_reach;
    o.invalid_backface_fraction = options->invalid_backface_fraction;
    if (options->progress) {
      const hemilight_progress_fn progress = options->progress;
      void* user = options->progress_user;
      o.progress = [progress, user](float f) { return progress(user, f) != 0; };
    }
    hemilight::hemicube_sampler_options so;
    so.resolution = options->resolution;
    so.raster.sky = scene->sky;
    so.integrate.extrapolate_wall_depth = options->extrapolate_wall_depth == 1;
    const hemilight::irradiance_sampler sampler =
        hemilight::make_hemicube_sampler(scene->scene, so, hemilight::resolve_thread_count(o.thread_count));
    hemilight::cache_result r;
    try {
      r = hemilight::cache_irradiance(reinterpret_cast<const glm::vec3*>(positions), reinterpret_cast<const glm::vec3*>(normals),
                                      count, sampler, o);
    } catch (const hemilight::error& e) {
      // "cache_irradiance: normals[3] ..." -> "hemilight_cache_irradiance: normals[3] ..."
      return hemilight::capi::set_error(hemilight::capi::to_c(e.code()), std::string("hemilight_") + e.what());
    }
    if (scene->lights) {
      // Direct light at every point, never interpolated (parallel; each point's value depends on
      // the point alone, so the result is the same for any thread count).
      const hemilight::scene& sc = *scene->scene;
      const hemilight::light_set& ls = *scene->lights;
      const glm::vec3* p = reinterpret_cast<const glm::vec3*>(positions);
      const glm::vec3* nn = reinterpret_cast<const glm::vec3*>(normals);
      hemilight::parallel_for(count, o.thread_count, 256, [&](int, std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) r.irradiance[i] += hemilight::direct_irradiance(sc, ls, p[i], glm::normalize(nn[i]));
      });
    }
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) irradiance_rgb[3 * i + size_t(c)] = r.irradiance[i][c];
    if (stats) {
      stats->hemicubes = r.stats.hemicubes;
      stats->records = r.stats.records;
      stats->seconds = r.stats.seconds;
      stats->invalid_samples = r.stats.invalid_samples;
    }
    return HEMILIGHT_OK;
  });
}

}  // extern "C"
