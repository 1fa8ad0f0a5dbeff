// libFuzzer harness: hemilight_cache_irradiance with points, normals and every option from the
// bytes, on a scene from the bytes. Checks the contract: finite outputs on OK, untouched ones on
// failure.
#include "fuzz_input.hpp"

#include <cstdio>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::input in(data, size);
  hemilight_scene* s = fuzz::make_scene(in);
  if (!s) return 0;
  s = fuzz::with_lights(in, s);
  const std::size_t count = std::size_t(in.small(0, 40));
  std::vector<float> pos = in.floats(3 * count), nrm(3 * count);
  for (std::size_t i = 0; i < count; ++i) {  // mostly unit normals along an axis, sometimes anything
    if (in.small(0, 7) == 0) {
      for (int c = 0; c < 3; ++c) nrm[3 * i + std::size_t(c)] = in.any_float(1.0f);
    } else {
      nrm[3 * i + std::size_t(in.small(0, 2))] = in.small(0, 1) ? 1.0f : -1.0f;
    }
  }
  hemilight_cache_options o;
  hemilight_cache_options_init(&o);
  o.resolution = 2 * in.small(0, 8);
  o.error_threshold = in.small(0, 3) == 0 ? in.any_float(1.0f) : 0.1f + 0.1f * float(in.small(0, 9));
  o.min_radius = in.small(0, 3) == 0 ? in.any_float(1.0f) : 0.0f;
  o.max_radius = in.small(0, 3) == 0 ? in.any_float(4.0f) : 0.0f;
  o.use_gradients = in.small(0, 2);
  o.thread_count = in.small(0, 3);
  o.weight = hemilight_cache_weight(in.small(0, 3));
  o.gradient_radius_limit = in.small(0, 1);
  o.neighbour_clamp = in.small(0, 1);
  o.shrink_disagreeing = in.small(0, 1);
  o.refine_disagreement = in.small(0, 1);
  if (in.small(0, 3) == 0) o.second_opinion = in.any_float(1.0f);
  if (in.small(0, 3) == 0) o.nearby_opinion = in.any_float(8.0f);
  if (in.small(0, 3) == 0) o.sole_record_reach = in.any_float(1.0f);
  if (in.small(0, 3) == 0) o.invalid_backface_fraction = in.any_float(1.0f);
  o.extrapolate_wall_depth = in.small(0, 1);
  o.second_order = in.small(0, 1);
  if (std::getenv("HEMILIGHT_FUZZ_VERBOSE")) {
    std::fprintf(stderr, "count %zu N %d a %g min %g max %g threads %d weight %d second_opinion %g nearby %g sole %g invalid %g\n", count,
                 o.resolution, double(o.error_threshold), double(o.min_radius), double(o.max_radius), o.thread_count, int(o.weight),
                 double(o.second_opinion), double(o.nearby_opinion), double(o.sole_record_reach), double(o.invalid_backface_fraction));
    for (std::size_t i = 0; i < count; ++i)
      std::fprintf(stderr, "  p (%g, %g, %g) n (%g, %g, %g)\n", double(pos[3 * i]), double(pos[3 * i + 1]), double(pos[3 * i + 2]),
                   double(nrm[3 * i]), double(nrm[3 * i + 1]), double(nrm[3 * i + 2]));
  }
  std::vector<float> out(3 * count + 1);
  hemilight_cache_stats st;
  hemilight_cache_stats_init(&st);
  fuzz::fill(out.data(), out.size() * sizeof(float));
  const hemilight_status r = hemilight_cache_irradiance(s, pos.data(), nrm.data(), count, &o, out.data(), &st);
  fuzz::check_finite(r, out.data(), 3 * count);
  fuzz::check_untouched(r, out.data(), out.size() * sizeof(float));
  hemilight_scene_release(s);
  return 0;
}
