// Record weights and predictions of the irradiance cache (internal, not installed): what the
// placement's hot loops, the interpolation and the Hessian fit share, inline. The public forms
// (record_weight, record_is_behind, interpolate_records) are in cache.hpp.
#pragma once

#include "hemilight/cache.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace hemilight::cache_detail {

constexpr float max_weight = 1e12f;  // caps Ward's 1/0 at a record's own position and normal
constexpr float behind_epsilon = 1e-6f;

inline float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// "(x, y, z)" for error messages.
inline std::string vec_str(const glm::vec3& v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

// The largest distance at which a record can have a positive weight: a R for both weightings.
inline float coverage_radius(const cache_record& r, const cache_options& o) { return o.error_threshold * r.radius; }

// The weight the coverage tests use: Ward's w where it passes 1/a (for both Ward weightings, so
// ward_continuous places the same records as ward), the Tabellion-Lamorlette w where positive;
// else 0. record_weight (the interpolation's weight) is this, less 1/a for ward_continuous.
// R is a cache_record or a record_lists::key (anything with position, normal and radius).
template <class R>
inline float coverage_weight(const R& r, const glm::vec3& x, const glm::vec3& n, const cache_options& o) {
  // Both weights are 0 beyond d = a R (Ward: d / R >= a makes w <= 1/a; T-L: d / (R/2) >= 2a makes
  // w <= 0). Points beyond it by more than float rounding (1e-4 relative: the arithmetic below
  // rounds by ~1e-7) are rejected without the square roots and the division: the same result.
  const glm::vec3 dx = x - r.position;
  const float reach = o.error_threshold * r.radius;
  if (glm::dot(dx, dx) > 1.0002f * reach * reach) return 0.0f;
  const float d = glm::length(dx);
  const float ndot = std::sqrt(std::max(0.0f, 1.0f - glm::dot(n, r.normal)));
  if (o.weight != cache_weight::tabellion_lamorlette) {
    const float denom = d / r.radius + ndot;
    const float w = denom > 1.0f / max_weight ? 1.0f / denom : max_weight;
    return w > 1.0f / o.error_threshold ? w : 0.0f;
  }
  const float k = 1.0f / (2.0f * o.error_threshold);
  const float w = 1.0f - k * std::max(d / (0.5f * r.radius), ndot / 0.12326f);
  return w > 0.0f ? w : 0.0f;
}

// record_weight and record_is_behind (cache.hpp), inline for the placement's hot loops.
template <class R>
inline float weight_of(const R& r, const glm::vec3& x, const glm::vec3& n, const cache_options& o) {
  const float w = coverage_weight(r, x, n, o);
  // w > 1/a here, so w - 1/a > 0 (IEEE subtraction of two different floats is never 0).
  return o.weight == cache_weight::ward_continuous && w > 0.0f ? w - 1.0f / o.error_threshold : w;
}
template <class R>
inline bool is_behind(const R& r, const glm::vec3& x, const glm::vec3& n) {
  return 0.5f * glm::dot(x - r.position, r.normal + n) < -behind_epsilon;
}

// What a record's first-order prediction needs, compact (a third of a cache_record): predict()
// gives bit for bit extrapolate(record, x, n, 1).
struct linear_model {
  glm::vec3 position, normal, irradiance;
  std::array<glm::vec3, 3> rotation_gradient, translation_gradient;
  explicit linear_model(const cache_record& r)
      : position(r.position), normal(r.normal), irradiance(r.irradiance), rotation_gradient(r.rotation_gradient),
        translation_gradient(r.translation_gradient) {}
  glm::vec3 predict(const glm::vec3& x, const glm::vec3& n) const {
    glm::vec3 e = irradiance;
    const glm::vec3 rot = glm::cross(normal, n);
    const glm::vec3 dx = x - position;
    for (int c = 0; c < 3; ++c)
      e[c] += glm::dot(rot, rotation_gradient[std::size_t(c)]) + glm::dot(dx, translation_gradient[std::size_t(c)]);
    return e;
  }
};

// A record's prediction at (x, n): order 0 = E_i, 1 = with the gradient terms, 2 = also with the
// second-order term 1/2 dx^T H dx, clamped per channel to +-a E_i (the error a allows: a record
// whose irradiance is 0, in an umbra, stays 0 instead of bending towards its lit neighbours).
inline glm::vec3 extrapolate(const cache_record& r, const glm::vec3& x, const glm::vec3& n, int order, float a = 1.0f) {
  glm::vec3 e = r.irradiance;
  if (order >= 1) {
    const glm::vec3 rot = glm::cross(r.normal, n);
    const glm::vec3 dx = x - r.position;
    for (int c = 0; c < 3; ++c)
      e[c] += glm::dot(rot, r.rotation_gradient[std::size_t(c)]) + glm::dot(dx, r.translation_gradient[std::size_t(c)]);
    if (order >= 2)
      for (int c = 0; c < 3; ++c) {
        const float limit = a * r.irradiance[c];
        e[c] += std::clamp(0.5f * glm::dot(dx, r.hessian[std::size_t(c)] * dx), -limit, limit);
      }
  }
  return e;
}

// The order of the predictions that options ask for.
inline int prediction_order(const cache_options& o) { return !o.use_gradients ? 0 : (o.second_order ? 2 : 1); }

}  // namespace hemilight::cache_detail
