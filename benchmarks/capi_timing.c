/* The timed loops of sweep_capi, in C99 as an engine calls the C ABI: each runs one entry point
 * over `count` points and returns the wall time in seconds (CLOCK_MONOTONIC), or a negative value
 * if a call failed (the message is printed). */
#define _POSIX_C_SOURCE 199309L
#include "capi_timing.h"

#include <stdio.h>
#include <time.h>

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double failed(const char* what) {
  printf("%s failed: %s\n", what, hemilight_last_error());
  return -1.0;
}

double capi_time_sample_irradiance(const hemilight_scene* scene, const float* positions, const float* normals, size_t count,
                                   int resolution, hemilight_irradiance* out) {
  size_t i;
  const double t0 = now();
  for (i = 0; i < count; ++i)
    if (hemilight_sample_irradiance(scene, positions + 3 * i, normals + 3 * i, resolution, &out[i]) != HEMILIGHT_OK)
      return failed("hemilight_sample_irradiance");
  return now() - t0;
}

double capi_time_sampler(hemilight_sampler* sampler, const float* positions, const float* normals, size_t count,
                         hemilight_irradiance* out) {
  size_t i;
  const double t0 = now();
  for (i = 0; i < count; ++i)
    if (hemilight_sampler_irradiance(sampler, positions + 3 * i, normals + 3 * i, &out[i]) != HEMILIGHT_OK)
      return failed("hemilight_sampler_irradiance");
  return now() - t0;
}

double capi_time_batch(const hemilight_scene* scene, const float* positions, const float* normals, size_t count,
                       int resolution, int threads, hemilight_irradiance* out) {
  const double t0 = now();
  if (hemilight_sample_irradiance_batch(scene, positions, normals, count, resolution, threads, out) != HEMILIGHT_OK)
    return failed("hemilight_sample_irradiance_batch");
  return now() - t0;
}

double capi_time_probes(const hemilight_scene* scene, const float* positions, size_t count, int resolution, int threads,
                        float* sh9_rgb) {
  const double t0 = now();
  if (hemilight_sample_probes(scene, positions, count, resolution, threads, sh9_rgb) != HEMILIGHT_OK)
    return failed("hemilight_sample_probes");
  return now() - t0;
}
