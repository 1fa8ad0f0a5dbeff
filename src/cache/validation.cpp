// The cache's checks of its options (cache.hpp) and of cache_irradiance's points (validation.hpp).
#include "validation.hpp"

#include "weights.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace hemilight {

void validate_cache_options(const cache_options& o, const std::string& who) {
  const std::string fn = who + ": ";
  if (!(o.error_threshold >= min_error_threshold && o.error_threshold <= 1.0f))
    throw_invalid_argument(fn + "error_threshold is " + std::to_string(o.error_threshold) +
                           "; it must be in [0.001, 1] (below 0.001 every point would be a record: use a hemicube per point)");
  if (!(o.min_radius >= 0.0f) || !std::isfinite(o.min_radius))
    throw_invalid_argument(fn + "min_radius is " + std::to_string(o.min_radius) + "; it must be finite and >= 0 (0 = automatic)");
  if (!(o.max_radius >= 0.0f) || !std::isfinite(o.max_radius))
    throw_invalid_argument(fn + "max_radius is " + std::to_string(o.max_radius) + "; it must be finite and >= 0 (0 = automatic)");
  if (o.min_radius > 0.0f && o.max_radius > 0.0f && o.min_radius > o.max_radius)
    throw_invalid_argument(fn + "min_radius " + std::to_string(o.min_radius) + " is larger than max_radius " +
                           std::to_string(o.max_radius));
  if (!(o.min_radius_spacings >= 1.0f && o.min_radius_spacings <= 1000.0f))
    throw_invalid_argument(fn + "min_radius_spacings is " + std::to_string(o.min_radius_spacings) + "; it must be in [1, 1000]");
  const cache_expert_options& x = o.expert;
  if (!(x.lone_record_change_limit >= 0.0f) || !std::isfinite(x.lone_record_change_limit))
    throw_invalid_argument(fn + "expert.lone_record_change_limit is " + std::to_string(x.lone_record_change_limit) +
                           "; it must be finite and >= 0 (0 = off)");
  if (!(x.lone_record_reach > 0.0f && x.lone_record_reach <= 1.0f))
    throw_invalid_argument(fn + "expert.lone_record_reach is " + std::to_string(x.lone_record_reach) + "; it must be in (0, 1] (1 = off)");
  if (!(x.lone_record_neighbour_reach >= 0.0f && x.lone_record_neighbour_reach <= 16.0f))
    throw_invalid_argument(fn + "expert.lone_record_neighbour_reach is " + std::to_string(x.lone_record_neighbour_reach) +
                           "; it must be in [0, 16] (0 = off)");
  if (!(o.invalid_backface_fraction >= 0.0f && o.invalid_backface_fraction <= 1.0f))
    throw_invalid_argument(fn + "invalid_backface_fraction is " + std::to_string(o.invalid_backface_fraction) +
                           "; it must be in [0, 1]");
}

namespace cache_detail {

void validate_cache_input(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const cache_options& o) {
  validate_cache_points(positions, normals, count, "cache_irradiance");
  validate_cache_options(o, "cache_irradiance");
}

}  // namespace cache_detail

void validate_cache_points(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const std::string& who) {
  const std::string fn = who + ": ";
  if (count == 0) throw_invalid_argument(fn + "count is 0: there are no points");
  if (!positions) throw_invalid_argument(fn + "positions is NULL");
  if (!normals) throw_invalid_argument(fn + "normals is NULL");
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3 &p = positions[i], &n = normals[i];
    if (!(std::fabs(p.x) <= max_coordinate && std::fabs(p.y) <= max_coordinate && std::fabs(p.z) <= max_coordinate))
      throw_invalid_argument(fn + "positions[" + std::to_string(i) + "] = " + cache_detail::vec_str(p) + " is not finite or beyond 1e18");
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
    const float len = glm::length(n);
    if (!(std::fabs(len - 1.0f) <= 1e-3f))
      throw_invalid_argument(fn + "normals[" + std::to_string(i) + "] = " + cache_detail::vec_str(n) + " has length " +
                             std::to_string(len) + "; it must be a unit vector");
  }
  // Distances between points are squared in float (weights, grids): the extent must keep them finite.
  const double diagonal = glm::length(hi - lo);
  if (diagonal > max_point_extent)
    throw_invalid_argument(fn + "the points span " + std::to_string(diagonal) + " units (bounding-box diagonal); at most " +
                           std::to_string(max_point_extent) + " is supported (squared distances must fit in float)");
}

}  // namespace hemilight
