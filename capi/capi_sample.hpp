// One hemicube at a point through the C ABI, shared by hemilight_sample_irradiance, the samplers
// and the batch (not installed): the checks of a point and the sample itself, so that every entry
// gives bitwise the same result for the same point.
#pragma once

#include "capi_internal.hpp"

#include "hemilight/hemicube.hpp"
#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"

#include <memory>
#include <string>

namespace hemilight::capi {

/// What one thread needs to sample points of one scene at one resolution: the rasterizer (its
/// direction tables and scratch), the integrator (its weight tables) and the buffer.
struct point_sampler {
  std::unique_ptr<hemicube_rasterizer> raster;
  std::unique_ptr<hemicube_integrator> integrator;
  hemicube_buffer buffer;

  /// Binds the scene (its sky) and makes the tables for `resolution` if they are not there.
  void prepare(const hemilight_scene& scene, int resolution);
  /// One point, checked before (check_point): render, integrate, the lights' direct irradiance.
  /// Returns false (out untouched) if a result is not finite.
  bool sample(const hemilight_scene& scene, int resolution, const float* position, const float* normal,
              hemilight_irradiance& out);
};

/// True if check_point would accept the point (no message built: for loops over many points).
bool point_ok(const float* position, const float* normal) noexcept;

/// Checks a point for `function`: position and normal non-NULL and finite, the normal nonzero.
/// Any finite nonzero normal is accepted, however small or large (unit_normal).
/// `where` prefixes the message's subject ("" or e.g. "point 7: "). On a bad point sets the error
/// and returns INVALID_ARGUMENT, else HEMILIGHT_OK.
hemilight_status check_point(const char* function, const std::string& where, const float* position, const float* normal);

/// The unit vector of a finite nonzero normal, computed in double (tiny and huge normals work).
glm::vec3 unit_normal(const float* normal);

}  // namespace hemilight::capi
