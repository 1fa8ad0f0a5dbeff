/* The C timing loops of sweep_capi (capi_timing.c). */
#ifndef HEMILIGHT_CAPI_TIMING_H
#define HEMILIGHT_CAPI_TIMING_H

#include "hemilight.h"

#ifdef __cplusplus
extern "C" {
#endif

double capi_time_sample_irradiance(const hemilight_scene* scene, const float* positions, const float* normals, size_t count,
                                   int resolution, hemilight_irradiance* out);
double capi_time_sampler(hemilight_sampler* sampler, const float* positions, const float* normals, size_t count,
                         hemilight_irradiance* out);
double capi_time_batch(const hemilight_scene* scene, const float* positions, const float* normals, size_t count,
                       int resolution, int threads, hemilight_irradiance* out);
double capi_time_probes(const hemilight_scene* scene, const float* positions, size_t count, int resolution, int threads,
                        float* sh9_rgb);

#ifdef __cplusplus
}
#endif

#endif
