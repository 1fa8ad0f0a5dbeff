// Accuracy of hemicube integration against closed forms, by resolution and estimator.
//   usage: sweep_integrate out.csv
// For each closed-form scene (tests/integrate_scenes.hpp), each N and each translation
// estimator (and great_arc with extrapolate_wall_depth): relative error of E, of the rotation gradient (where the closed form gives it), and
// of the translation gradient (|g - g_ref| / |g_ref|) against central differences of the closed
// form. Hemicubes are rendered by the independent reference ray caster, so the figures measure
// the integrator alone (no rasterizer error).
#include "hemilight/integrate.hpp"

#include "integrate_scenes.hpp"

#include <chrono>
#include <cstdio>

using namespace hemilight;
using namespace hemilight::test;

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "integrate_sweep.csv";
  FILE* out = std::fopen(path, "w");
  if (!out) {
    std::fprintf(stderr, "sweep_integrate: cannot write '%s'\n", path);
    return 1;
  }
  std::fprintf(out, "scene,N,estimator,E_rel_err,g_r_rel_err,g_t_rel_err,g_t_ref_norm,E_ref\n");
  const int max_n = argc > 2 ? std::atoi(argv[2]) : 512;
  for (const closed_form_scene& s :
       {unoccluded_emitter(), occluded_emitter(), beside_wall_under_sky(), lit_room(), emitter_seen_edge_on(0.002)}) {
    const double e_ref = s.irradiance(s.position, s.normal);
    const glm::dvec3 gt_ref = closed_form_translation_gradient(s);
    // Rotation gradient of the closed form (central differences of E(x, n rotated)); the
    // wall scene's wall foot lies on the horizon, where rotating breaks the closed form.
    const bool has_gr = s.name != "beside a tall wall under a sky";
    const glm::dvec3 gr_ref = has_gr ? closed_form_rotation_gradient(s) : glm::dvec3(0.0);
    for (int n = 16; n <= max_n; n *= 2) {
      // Rolled 0.3 rad so the texel grid is not aligned with the scenes' edges.
      const hemicube_buffer buf = raycast_hemicube(s.tris, s.sky, s.position, rolled_frame(s.normal, 0.3), n);
      // The three estimators, then great_arc with extrapolate_wall_depth.
      for (int variant = 0; variant < 4; ++variant) {
        const translation_estimator est = variant == 0 ? translation_estimator::simple
                                          : variant == 1 ? translation_estimator::classified
                                                         : translation_estimator::great_arc;
        integrate_options o;
        o.translation = est;
        o.extrapolate_wall_depth = variant == 3;
        o.min_wall_distance = 1e-6f;  // no clamp: measure the estimator itself
        const irradiance_sample r = integrate(buf, o);
        // channel 0 has radiance 1 x tint.x = 1 (sky scenes: sky 1)
        const double e = r.irradiance.x;
        const glm::dvec3 gt(r.translation_gradient[0]);
        const glm::dvec3 gr(r.rotation_gradient[0]);
        const char* name = variant == 0 ? "simple" : variant == 1 ? "classified" : variant == 2 ? "great_arc" : "great_arc_extrapolated";
        std::fprintf(out, "%s,%d,%s,%.6g,%.6g,%.6g,%.6g,%.6g\n", s.name.c_str(), n, name, std::fabs(e - e_ref) / e_ref,
                     has_gr ? glm::length(gr - gr_ref) / glm::length(gr_ref) : -1.0,
                     glm::length(gt - gt_ref) / glm::length(gt_ref), glm::length(gt_ref), e_ref);
      }
    }
  }
  std::fclose(out);
  std::printf("wrote %s\n", path);
  return 0;
}
