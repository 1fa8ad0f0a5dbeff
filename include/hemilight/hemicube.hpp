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
/// The radiance is planar (three planes of one float per texel, R then G then B), the layout the
/// integrator's SIMD loops read and the rasterizer writes in runs.
///
/// Memory: 17 bytes per texel (N = 64: 204 KiB). Reuse one buffer per thread: resize() does not
/// reallocate when the resolution does not grow.
struct hemicube_buffer {
  int resolution = 0;          ///< N (even, 2..4096); 0 for an empty buffer
  glm::vec3 position{0.0f};    ///< world-space point the hemicube was rendered from
  frame basis{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  ///< world-space frame; basis.n is the normal (local +z)
  std::vector<float> radiance;       ///< 3 planes: radiance[c * texel_count() + i], c = 0 R, 1 G, 2 B
  std::vector<float> distance;       ///< one float per texel, > 0, +inf for misses
  std::vector<std::uint8_t> flags;   ///< one texel_flags mask per texel

  /// Sizes the arrays for resolution N (contents unspecified). Throws error(invalid_argument)
  /// for an invalid N.
  void resize(int n) {
    check_hemicube_resolution(n, "hemicube_buffer::resize");
    const std::size_t count = hemicube_texel_count(n);
    resolution = n;
    radiance.resize(3 * count);
    distance.resize(count);
    flags.resize(count);
  }

  std::size_t texel_count() const noexcept { return distance.size(); }

  /// The plane of channel c (0 = R, 1 = G, 2 = B): texel_count() floats. Precondition: c in [0, 2].
  float* channel(int c) noexcept { return radiance.data() + static_cast<std::size_t>(c) * distance.size(); }
  const float* channel(int c) const noexcept { return radiance.data() + static_cast<std::size_t>(c) * distance.size(); }

  /// RGB radiance of texel i (i < texel_count(), unchecked).
  glm::vec3 radiance_at(std::size_t i) const noexcept {
    const std::size_t n = distance.size();
    return {radiance[i], radiance[n + i], radiance[2 * n + i]};
  }
  /// Sets the RGB radiance of texel i (i < texel_count(), unchecked).
  void set_radiance(std::size_t i, const glm::vec3& l) noexcept {
    const std::size_t n = distance.size();
    radiance[i] = l.x;
    radiance[n + i] = l.y;
    radiance[2 * n + i] = l.z;
  }

  /// Fills every texel with "nothing hit": radiance = sky (RGB), distance = +inf, flag miss.
  void fill_sky(const glm::vec3& sky) noexcept {
    for (std::size_t i = 0; i < distance.size(); ++i) {
      set_radiance(i, sky);
      distance[i] = std::numeric_limits<float>::infinity();
      flags[i] = texel_miss;
    }
  }
};

/// Where a texel lands in the unfolded-cross picture of a hemicube: a 2N x 2N image with the top
/// face at [N/2, 3N/2)^2 and each side face folded out next to the edge it shares with the top
/// face (horizon towards the middle). Picture row 0 is the top of the picture and hemicube +y
/// points up in it, +x to the right. Returns (column, row) of the picture. Precondition: N valid
/// and t inside its face (asserted by hemicube_texel_index's checks where used). Cost: O(1).
inline glm::ivec2 hemicube_cross_pixel(int n, hemicube_texel t) noexcept {
  const int h = n / 2;
  int px = 0, py = 0;  // py measured upwards (hemicube +y)
  switch (t.face) {
    case hemicube_face::top: px = h + t.x; py = h + t.y; break;
    case hemicube_face::pos_x: px = h + n + t.y; py = h + t.x; break;          // columns along +y
    case hemicube_face::neg_x: px = h - 1 - t.y; py = h + n - 1 - t.x; break;  // columns along -y
    case hemicube_face::pos_y: px = h + n - 1 - t.x; py = h + n + t.y; break;  // columns along -x
    case hemicube_face::neg_y: px = h + t.x; py = h - 1 - t.y; break;          // columns along +x
  }
  return {px, 2 * n - 1 - py};
}

/// Debug aid: writes a hemicube buffer as three 2N x 2N float EXR images laid out as the
/// unfolded cross of hemicube_cross_pixel (the four corners, outside the cross, are 0):
///   <path_prefix>_radiance.exr  RGB radiance;
///   <path_prefix>_distance.exr  distance in R, G and B (misses written as 0, not +inf, so
///                               viewers can scale the picture; the flags image shows them);
///   <path_prefix>_flags.exr     R = 1 for texel_miss, G = 1 for texel_back_face, B = 1 on every
///                               texel of the cross.
/// Throws error(invalid_argument) for a buffer whose arrays do not match its resolution, and
/// error(io) as write_exr (image_io.hpp). Cost: O(N^2) plus the file writes.
void write_hemicube_exr(const std::string& path_prefix, const hemicube_buffer& buffer);

}  // namespace hemilight
