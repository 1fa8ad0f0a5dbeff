// The C ABI's light probes: hemilight_sample_probes (SH9 per point, probes.hpp) and
// hemilight_sh9_irradiance.
#include "capi_internal.hpp"

#include "hemilight/geometry.hpp"
#include "hemilight/probes.hpp"

#include <cmath>
#include <string>

namespace {

using hemilight::capi::all_finite;
using hemilight::capi::guarded;
using hemilight::capi::invalid;

// with_backfaces: hemilight_sample_probes_with_backfaces (backface_fraction is required with count > 0).
hemilight_status sample_probes(const char* fn, const hemilight_scene* scene, const float* positions, size_t count,
                               int resolution, int thread_count, float* sh9_rgb, bool with_backfaces,
                               float* backface_fraction) {
  return guarded(fn, [&] {
    // Step 1: the arguments and every point, before anything is rendered; every argument whatever
    // the count (the arrays may be NULL only when it is 0: then nothing is done).
    if (!scene) return invalid(fn, "scene is NULL");
    const std::string with_count = " but count is " + std::to_string(count);
    if (count > 0 && !positions) return invalid(fn, "positions is NULL" + with_count);
    if (count > 0 && !sh9_rgb) return invalid(fn, "sh9_rgb is NULL" + with_count);
    if (count > 0 && with_backfaces && !backface_fraction) return invalid(fn, "backface_fraction is NULL" + with_count);
    if (count > hemilight::max_scene_elements)
      return invalid(fn, "count " + std::to_string(count) + " is over the limit of " +
                             std::to_string(hemilight::max_scene_elements) + " probes per call");
    if (const hemilight_status st = hemilight::capi::check_resolution(fn, resolution)) return st;
    if (thread_count < 0) return invalid(fn, "thread_count is " + std::to_string(thread_count) + "; it must be >= 0 (0 = all cores)");
    for (std::size_t i = 0; i < count; ++i)
      if (!all_finite(positions + 3 * i, 3) || std::fabs(positions[3 * i]) > hemilight::max_coordinate ||
          std::fabs(positions[3 * i + 1]) > hemilight::max_coordinate || std::fabs(positions[3 * i + 2]) > hemilight::max_coordinate)
        return invalid(fn, "point " + std::to_string(i) + ": position (" + std::to_string(positions[3 * i]) + ", " +
                               std::to_string(positions[3 * i + 1]) + ", " + std::to_string(positions[3 * i + 2]) +
                               ") is not finite or beyond 1e18");
    if (count == 0) return HEMILIGHT_OK;
    // Step 2: the probes (into the library's own arrays: nothing is written on failure).
    std::vector<glm::vec3> p(count);
    for (std::size_t i = 0; i < count; ++i) p[i] = {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]};
    hemilight::probe_options o;
    o.resolution = resolution;
    o.thread_count = thread_count;
    o.raster.sky = scene->sky;
    o.lights = scene->lights;
    o.raster.edge_coverage = scene->edge_coverage;
    const hemilight::probe_result r = hemilight::sample_probes(scene->scene, p.data(), count, o);
    // Finite on OK: radiance is bounded (max_radiance) but a light's I / d^2 next to a probe is not.
    for (std::size_t i = 0; i < count; ++i)
      if (!all_finite(&r.probes[i][0].x, 27))
        return invalid(fn, "point " + std::to_string(i) + ": the probe overflows float (a light too intense or too close?)");
    // Step 3: out, sh9_rgb[27 i + 3 k + c].
    for (std::size_t i = 0; i < count; ++i)
      for (std::size_t k = 0; k < 9; ++k)
        for (int c = 0; c < 3; ++c) sh9_rgb[27 * i + 3 * k + std::size_t(c)] = r.probes[i][k][c];
    if (backface_fraction)
      for (std::size_t i = 0; i < count; ++i) backface_fraction[i] = r.backface_fraction[i];
    return HEMILIGHT_OK;
  });
}

}  // namespace

extern "C" {

hemilight_status hemilight_sample_probes(const hemilight_scene* scene, const float* positions, size_t count, int resolution,
                                         int thread_count, float* sh9_rgb) {
  return sample_probes("hemilight_sample_probes", scene, positions, count, resolution, thread_count, sh9_rgb, false, nullptr);
}

hemilight_status hemilight_sample_probes_with_backfaces(const hemilight_scene* scene, const float* positions, size_t count,
                                                        int resolution, int thread_count, float* sh9_rgb,
                                                        float* backface_fraction) {
  return sample_probes("hemilight_sample_probes_with_backfaces", scene, positions, count, resolution, thread_count, sh9_rgb,
                       true, backface_fraction);
}

hemilight_status hemilight_sh9_irradiance(const float sh9_rgb[27], const float normal[3], float irradiance[3]) {
  const char* fn = "hemilight_sh9_irradiance";
  return guarded(fn, [&] {
    if (!sh9_rgb) return invalid(fn, "sh9_rgb is NULL");
    if (!normal) return invalid(fn, "normal is NULL");
    if (!irradiance) return invalid(fn, "irradiance is NULL");
    if (!all_finite(sh9_rgb, 27)) return invalid(fn, "sh9_rgb holds a NaN or an infinity");
    if (!all_finite(normal, 3)) return invalid(fn, "normal is not finite");
    if (normal[0] == 0.0f && normal[1] == 0.0f && normal[2] == 0.0f) return invalid(fn, "normal has no direction (zero length)");
    const glm::dvec3 nd(normal[0], normal[1], normal[2]);
    const glm::vec3 n(nd / glm::length(nd));  // in double: tiny and huge normals work
    hemilight::sh9_rgb c;
    for (std::size_t k = 0; k < 9; ++k) c[k] = {sh9_rgb[3 * k], sh9_rgb[3 * k + 1], sh9_rgb[3 * k + 2]};
    const glm::vec3 e = hemilight::sh9_irradiance(c, n);
    if (!all_finite(&e.x, 3)) return invalid(fn, "the irradiance overflows float: the coefficients are too large");
    for (int k = 0; k < 3; ++k) irradiance[k] = e[k];
    return HEMILIGHT_OK;
  });
}

}  // extern "C"
