#include "hemilight/hemicube.hpp"

#include "hemilight/image_io.hpp"

#include <cmath>
#include <string>

namespace hemilight {

void write_hemicube_exr(const std::string& path_prefix, const hemicube_buffer& buffer) {
  const int n = buffer.resolution;
  if (!is_valid_hemicube_resolution(n))
    throw_invalid_argument("write_hemicube_exr: buffer resolution " + std::to_string(n) + " is invalid");
  const std::size_t count = hemicube_texel_count(n);
  if (buffer.radiance.size() != 3 * count || buffer.distance.size() != count || buffer.flags.size() != count)
    throw_invalid_argument("write_hemicube_exr: buffer arrays do not match its resolution " + std::to_string(n) +
                           " (call resize)");
  image radiance = image::make(2 * n, 2 * n, 3), distance = image::make(2 * n, 2 * n, 3),
        flags = image::make(2 * n, 2 * n, 3);
  for (std::size_t i = 0; i < count; ++i) {
    const glm::ivec2 px = hemicube_cross_pixel(n, hemicube_texel_from_index(n, i));
    float* r = radiance.at(px.x, px.y);
    float* d = distance.at(px.x, px.y);
    float* f = flags.at(px.x, px.y);
    for (int c = 0; c < 3; ++c) r[c] = buffer.channel(c)[i];
    const float dist = std::isfinite(buffer.distance[i]) ? buffer.distance[i] : 0.0f;
    d[0] = d[1] = d[2] = dist;
    f[0] = (buffer.flags[i] & texel_miss) ? 1.0f : 0.0f;
    f[1] = (buffer.flags[i] & texel_back_face) ? 1.0f : 0.0f;
    f[2] = 1.0f;
  }
  write_exr(path_prefix + "_radiance.exr", radiance);
  write_exr(path_prefix + "_distance.exr", distance);
  write_exr(path_prefix + "_flags.exr", flags);
}

}  // namespace hemilight
