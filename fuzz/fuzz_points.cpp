// libFuzzer harness: a scene (triangles, sky, lights) and points from the bytes, through
// hemilight_sample_irradiance, the samplers, hemilight_sample_irradiance_batch, the probes and
// hemilight_sh9_irradiance. Checks the contract: finite outputs on OK, untouched ones on failure.
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::input in(data, size);
  hemilight_scene* s = fuzz::make_scene(in);
  if (!s) return 0;
  s = fuzz::with_lights(in, s);
  const int n = 2 * in.small(0, 9);  // 0 (bad) .. 18
  const std::size_t count = std::size_t(in.small(0, 6));
  const std::vector<float> pos = in.floats(3 * count), nrm = in.floats(3 * count);
  std::vector<hemilight_irradiance> out(count + 1);
  fuzz::fill(out.data(), out.size() * sizeof(hemilight_irradiance));
  if (count > 0) {
    hemilight_status st = hemilight_sample_irradiance(s, pos.data(), nrm.data(), n, out.data());
    fuzz::check_finite(st, out[0].irradiance, 3);
    fuzz::check_untouched(st, out.data(), sizeof(hemilight_irradiance));
    hemilight_sampler* smp = nullptr;
    if (hemilight_sampler_create(s, n, &smp) == HEMILIGHT_OK) {
      fuzz::fill(out.data(), sizeof(hemilight_irradiance));
      st = hemilight_sampler_irradiance(smp, pos.data(), nrm.data(), out.data());
      fuzz::check_finite(st, out[0].irradiance, 3);
      fuzz::check_untouched(st, out.data(), sizeof(hemilight_irradiance));
      hemilight_sampler_release(smp);
    }
  }
  fuzz::fill(out.data(), out.size() * sizeof(hemilight_irradiance));
  hemilight_status st = hemilight_sample_irradiance_batch(s, pos.data(), nrm.data(), count, n, in.small(0, 3), out.data());
  for (std::size_t i = 0; i < count; ++i) fuzz::check_finite(st, out[i].irradiance, 3);
  fuzz::check_untouched(st, out.data(), out.size() * sizeof(hemilight_irradiance));
  std::vector<float> sh(27 * count + 1), back(count + 1);
  fuzz::fill(sh.data(), sh.size() * sizeof(float));
  fuzz::fill(back.data(), back.size() * sizeof(float));
  st = hemilight_sample_probes_with_backfaces(s, pos.data(), count, n, in.small(0, 2), sh.data(), back.data());
  fuzz::check_finite(st, sh.data(), 27 * count);
  fuzz::check_finite(st, back.data(), count);
  fuzz::check_untouched(st, sh.data(), sh.size() * sizeof(float));
  if (count > 0 && st == HEMILIGHT_OK) {
    float e[3];
    fuzz::fill(e, sizeof e);
    const hemilight_status se = hemilight_sh9_irradiance(sh.data(), nrm.data(), e);
    fuzz::check_finite(se, e, 3);
    fuzz::check_untouched(se, e, sizeof e);
  }
  hemilight_scene_release(s);
  return 0;
}
