// hemilight/hemicube.hpp — the hemicube buffer: what a surface point sees, texel by texel.
//
// The rasterizer (raster.hpp) fills it; the integrator (integrate.hpp) reduces it to irradiance,
// gradients and distances. Texels follow the layout of geometry.hpp (3 N^2 texels, top face
// first, row-major). The buffer also carries the point and the world frame it was rendered
// with, so world-space gradients can be formed from it.
#pragma once

#include "hemilight/geometry.hpp"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace hemilight {

/// Per-texel flags of a hemicube buffer (bit mask).
enum texel_flags : std::uint8_t {
  texel_hit_front = 0,      ///< the texel centre ray hits the front face of a triangle (or a two-sided one)
  texel_miss = 1u << 0,     ///< nothing hit: radiance is the sky's, distance is +inf
  texel_back_face = 1u << 1 ///< hits the back face of a one-sided triangle: radiance 0
};

/// What a hemicube sees: per texel the outgoing radiance (RGB) through the texel centre, the
/// Euclidean distance from `position` to the visible point along the texel's centre direction
/// (not the projected depth; +inf where nothing is hit), and texel_flags.
///
/// Memory: 17 bytes per texel (N = 64: 204 KiB). Reuse one buffer per thread: resize() does not
/// reallocate when the resolution does not grow.
struct hemicube_buffer {
  int resolution = 0;          ///< N (even, 2..4096); 0 for an empty buffer
  glm::vec3 position{0.0f};    ///< world-space point the hemicube was rendered from
  frame basis{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  ///< world-space frame; basis.n is the normal (local +z)
  std::vector<float> radiance;       ///< 3 floats per texel, RGB interleaved: radiance[3 i + c]
  std::vector<float> distance;       ///< one float per texel, > 0, +inf for misses
  std::vector<std::uint8_t> flags;   ///< one texel_flags mask per texel

  /// Sizes the arrays for resolution N (contents unspecified). Throws error(invalid_argument)
  /// for an invalid N.
  void resize(int n) {
    if (!is_valid_hemicube_resolution(n))
      throw_invalid_argument("hemicube_buffer::resize: resolution " + std::to_string(n) +
                             " is invalid: it must be even and in [2, 4096]");
    const std::size_t count = hemicube_texel_count(n);
    resolution = n;
    radiance.resize(3 * count);
    distance.resize(count);
    flags.resize(count);
  }

  std::size_t texel_count() const noexcept { return distance.size(); }

  /// Fills every texel with "nothing hit": radiance = sky (RGB), distance = +inf, flag miss.
  void fill_sky(const glm::vec3& sky) noexcept {
    for (std::size_t i = 0; i < distance.size(); ++i) {
      radiance[3 * i + 0] = sky.x;
      radiance[3 * i + 1] = sky.y;
      radiance[3 * i + 2] = sky.z;
      distance[i] = std::numeric_limits<float>::infinity();
      flags[i] = texel_miss;
    }
  }
};

}  // namespace hemilight
